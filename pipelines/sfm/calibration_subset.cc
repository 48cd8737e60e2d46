#include "pipelines/sfm/calibration_subset.h"

#include <cmath>

#include "colmap_ext/util/error.h"
#include "database/feature_types.h"

namespace portcal {

void CalibrationSubsetOptions::Check() const {
  if (num_images < 2) throw OptionError("--Subset.num_images", num_images, ">= 2");
  if (min_num_inliers < 1) throw OptionError("--Subset.min_num_inliers", min_num_inliers, ">= 1");
}

namespace {

bool Linked(image_t a, image_t b, const std::map<image_pair_t, int>& inliers, int min_num_inliers) {
  const auto it = inliers.find(ImagePairToPairId(a, b));
  return it != inliers.end() && it->second >= min_num_inliers;
}

}  // namespace

CalibrationSubset ChooseCalibrationSubset(const std::vector<image_t>& ordered,
                                          const std::map<image_pair_t, int>& inliers,
                                          const CalibrationSubsetOptions& options) {
  options.Check();
  CalibrationSubset subset;
  if (ordered.empty()) return subset;
  const size_t n = ordered.size();
  // The step along the order that spreads num_images over the survey.
  const double stride = std::max(1.0, static_cast<double>(n - 1) / (options.num_images - 1));
  size_t last = 0;
  subset.images.push_back(ordered[0]);
  while (last + 1 < n) {
    const size_t goal = std::min(
        n - 1, std::max(last + 1, static_cast<size_t>(std::lround(
                                      static_cast<double>(subset.images.size()) * stride))));
    // The farthest image up to the goal that the last kept one is linked
    // to; failing that, the nearest one beyond it.
    size_t next = 0;
    for (size_t j = goal; j > last && next == 0; --j) {
      if (Linked(ordered[last], ordered[j], inliers, options.min_num_inliers)) next = j;
    }
    for (size_t j = goal + 1; j < n && next == 0; ++j) {
      if (Linked(ordered[last], ordered[j], inliers, options.min_num_inliers)) next = j;
    }
    if (next == 0) {  // nothing later is linked: a break, go on from the goal
      ++subset.num_breaks;
      next = goal;
    }
    subset.images.push_back(ordered[next]);
    last = next;
  }
  return subset;
}

}  // namespace portcal
