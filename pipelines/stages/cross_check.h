// `portcal cross_check`: portcal's in-air calibration against mrcal's
// solution of the same corners, and cross-validation of the intrinsics on
// disjoint subsets of the views (mrcal's recommended test of whether a
// calibration is good enough). Reads the database only; writes
// cross_check.txt / .yaml, the heat maps and mrcal's .cameramodel into the
// output directory.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/crosscheck/cross_check_report.h"

namespace portcal {

struct CrossCheckOptions {
  std::string database_path;
  std::string input_calibration;  // portcal's calibration.yaml of the camera
  std::string output_path;        // directory (created)
  int camera_id = -1;             // -1: the only camera with observations
  int folds = 0;                  // --CrossCheck.folds: 0 (none) or >= 2
  double max_diff_px = 0.5;       // --CrossCheck.max_diff_px, at the 95th percentile
  int gridn_width = 60;           // --CrossCheck.gridn_width
  // mrcal's solve as mrcal-calibrate-cameras runs it by default.
  bool mrcal_board_warp = true;
  bool mrcal_outlier_rejection = true;
  bool mrcal_regularization = true;
  int num_threads = 2;
  void Check() const;  // throws OptionError naming the option
};

// Throws InputError (files, model mrcal cannot express), NumericalError.
using CrossCheckSummary = CrossCheckResult;

CrossCheckSummary RunCrossCheck(const CrossCheckOptions& options, ProgressSink& progress);

}  // namespace portcal
