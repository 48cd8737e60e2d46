#include "pipelines/sfm/model_mapping.h"

#include <algorithm>
#include <map>
#include <string>

#include "colmap_ext/util/error.h"
#include "pipelines/sfm/calibration_start.h"

namespace portcal {

void ModelMappingOptions::Check() const {
  focal_start.Check();
  radial_start.Check();
  if (housing) housing->ValidateInput("--Housing.params");
  mapper.Check();
}

std::vector<MappedModel> MapModels(const SfmInputs& inputs, const ModelMappingOptions& options,
                                   ProgressSink& progress) {
  std::map<camera_t, HousedCamera> cameras = inputs.cameras;
  if (options.housing) ReplaceHousings(*options.housing, &cameras);
  IncrementalMapperOptions mapper = options.mapper;
  const std::set<camera_t> from_markers =
      StartFocalFromMarkers(inputs, options.init_focal_from_markers, &cameras);
  if (!from_markers.empty()) {
    mapper.max_focal_ratio_to_start =
        std::min(mapper.max_focal_ratio_to_start, kMaxFocalRatioToMarkers);
  }
  const std::set<camera_t> from_pairs = StartFocalFromPairs(
      inputs, options.init_focal_from_pairs, options.focal_start, from_markers, &cameras);
  for (const auto& [id, camera] : cameras) {
    if (!camera.camera.has_prior_focal_length && !from_markers.count(id) && !from_pairs.count(id))
      mapper.guessed_focal_cameras.insert(id);
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
