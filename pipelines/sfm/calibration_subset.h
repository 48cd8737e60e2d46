// A subset of a survey to self-calibrate the housing on, then map every
// image with the housing held (docs/auto_calibration.md, "A subset"): the
// images spread evenly along the acquisition order (every line of a
// lawnmower survey, every altitude it flew, in proportion), each one
// sharing a verified pair with the one kept before it, so the subset maps
// as one connected model; pairs across lines come with the images both
// sides kept.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "colmap_ext/util/types.h"

namespace portcal {

struct CalibrationSubsetOptions {
  int num_images = 300;  // --Subset.num_images: the subset's size (more where the pairs fall short)
  int min_num_inliers = 100;  // --Subset.min_num_inliers: a link of the chain
  void Check() const;         // throws OptionError naming the option
};

struct CalibrationSubset {
  std::vector<image_t> images;  // in acquisition order
  // Where no later image within reach shares a verified pair of
  // min_num_inliers with the last kept one: the chain restarts there (the
  // subset may map as more than one model).
  int num_breaks = 0;
};

// `ordered`: every image, in acquisition order (names sorted). `inliers`:
// verified pairs (pair id -> inlier matches).
CalibrationSubset ChooseCalibrationSubset(const std::vector<image_t>& ordered,
                                          const std::map<image_pair_t, int>& inliers,
                                          const CalibrationSubsetOptions& options);

}  // namespace portcal
