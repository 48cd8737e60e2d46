// The mapper's start and its models (refractive_mapper's core, which
// auto_calibrator calls in memory): the housing override, the focal length
// from the ArUco markers, the first radial term from the verified matches,
// then the incremental pipeline (incremental_pipeline.h).
#pragma once

#include <optional>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/sfm/focal_start.h"
#include "pipelines/sfm/incremental_pipeline.h"
#include "pipelines/sfm/radial_start.h"

namespace portcal {

struct ModelMappingOptions {
  IncrementalMapperOptions mapper;
  std::optional<Housing> housing;  // for every camera; none: the inputs'
  // The focal length from the markers before mapping: always, never, or
  // (nullopt) when the camera has no prior focal length.
  std::optional<bool> init_focal_from_markers;
  // The focal length from the verified pairs (focal_start.h) for a camera
  // the markers gave none: always, never, or (nullopt) when the camera has
  // no prior focal length.
  std::optional<bool> init_focal_from_pairs;
  FocalStartOptions focal_start;
  // The lens's first radial term from the verified matches (radial_start.h)
  // before mapping: always, never, or (nullopt) when the camera has no
  // prior focal length, its distortion is all zero, the mapper refines it
  // and the model is not a fisheye.
  std::optional<bool> init_radial_from_matches;
  RadialStartOptions radial_start;
  void Check() const;  // throws OptionError naming the option
};

// The models, largest first; NumericalError when none could be started.
std::vector<MappedModel> MapModels(const SfmInputs& inputs, const ModelMappingOptions& options,
                                   ProgressSink& progress);

}  // namespace portcal
