// Incremental structure-from-motion on refracted rays, the policy: an
// initial pair by relative pose, then one image at a time
// (incremental_mapper.h: the steps), global adjustments as the model grows
// and the calibration refined until it settles, models started again from
// another pair when their intrinsics keep coming out implausible, several
// models when the scene falls apart.
#pragma once

#include <map>
#include <vector>

#include "colmap_ext/util/progress.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/incremental_mapper_options.h"

namespace portcal {

// A global adjustment that refined the intrinsics or housing.
struct CalibrationRefinement {
  int num_images = 0;  // in the model then
  // How far it moved the image, pixels at the scene's median depth
  // (MaxImageShiftPx); infinity where not measured: on fewer than
  // ba_calibration_settled_min_images, or when the adjustment did not
  // converge.
  double image_shift_px = 0;
  // The calibration counts as settled after this one: held from here on,
  // except in the model's final adjustments (which are recorded too).
  bool settled = false;
};

struct MappedModel {
  Reconstruction reconstruction;
  image_pair_t initial_pair = 0;  // the pair it grew from
  std::vector<CalibrationRefinement>
      calibration_refinements;  // in order; the final adjustment's last
};

// Grows models until no image can be added; returns them largest first.
std::vector<MappedModel> RunIncrementalMapper(const SfmInputs& inputs,
                                              const std::map<camera_t, HousedCamera>& cameras,
                                              const IncrementalMapperOptions& options,
                                              ProgressSink& progress);

}  // namespace portcal
