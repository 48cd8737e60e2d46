// `portcal calibration_subset_selector`: the images of a matched survey to
// self-calibrate the housing on (pipelines/sfm/calibration_subset.h),
// written as an image list for refractive_mapper --image_list_path. The
// cheap path on a large survey: map and refine the subset with the housing
// refined, then map every image with that housing held.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/sfm/calibration_subset.h"

namespace portcal {

struct CalibrationSubsetSelectorOptions {
  std::string database_path;  // matched
  std::string output_path;    // the image list (a text file, replaced)
  CalibrationSubsetOptions subset;
  void Check() const;  // throws OptionError naming the option
};

struct CalibrationSubsetSelectorSummary {
  int num_images = 0;  // in the database
  int num_selected = 0;
  int num_breaks = 0;  // see CalibrationSubset
};

// Throws InputError (no verified pairs) or DatabaseError; a failed run
// leaves no list.
CalibrationSubsetSelectorSummary RunCalibrationSubsetSelector(
    const CalibrationSubsetSelectorOptions& options, ProgressSink& progress);

}  // namespace portcal
