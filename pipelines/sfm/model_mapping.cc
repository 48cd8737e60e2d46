#include "pipelines/sfm/model_mapping.h"

#include <algorithm>
#include <map>
#include <string>

#include "colmap_ext/util/error.h"
#include "pipelines/sfm/calibration_start.h"

namespace portcal {

void ModelMappingOptions::Check() const {
  radial_start.Check();
  if (housing) housing->ValidateInput("--Housing.params");
  mapper.Check();
}

std::vector<MappedModel> MapModels(const SfmInputs& inputs, const ModelMappingOptions& options,
                                   ProgressSink& progress) {
  std::map<camera_t, HousedCamera> cameras = inputs.cameras;
  if (options.housing) ReplaceHousings(*options.housing, &cameras);
  IncrementalMapperOptions mapper = options.mapper;
  if (StartFocalFromMarkers(inputs, options.init_focal_from_markers, &cameras)) {
    mapper.max_focal_ratio_to_start =
        std::min(mapper.max_focal_ratio_to_start, kMaxFocalRatioToMarkers);
  }
  StartRadialFromMatches(inputs, options.init_radial_from_matches,
                         options.mapper.ba_refine_extra_params, options.radial_start, &cameras);
  std::vector<MappedModel> models = RunIncrementalMapper(inputs, cameras, mapper, progress);
  if (models.empty()) {
    throw NumericalError("refractive_mapper: no model could be initialised from " +
                         std::to_string(inputs.pair_inliers.size()) +
                         " verified pairs (too few inlier matches or too little parallax; see "
                         "--Mapper.init_min_num_inliers and --Mapper.init_min_tri_angle)");
  }
  return models;
}

}  // namespace portcal
