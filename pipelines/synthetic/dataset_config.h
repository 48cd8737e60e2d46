// The dataset description `portcal synthesize --config` reads: the format of
// the config_used.yaml files beside the shared rendered sets, plus stereo,
// the other targets, survey mode and the underwater image effects.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/synthetic/renderer.h"
#include "pipelines/synthetic/target_builder.h"
#include "pipelines/synthetic/trajectory.h"
#include "pipelines/synthetic/view_sampler.h"

namespace portcal {

struct DatasetConfig {
  std::string name = "synthetic";
  std::string description;
  uint64_t seed = 1;
  int num_images = 25;
  Camera camera;
  std::optional<Housing> housing;
  // Stereo: a second camera (default: the first's model and housing).
  bool stereo = false;
  Rigid3d cam2_from_cam1;
  Camera camera2;
  std::optional<Housing> housing2;
  // Either a target seen from random views, or a survey over a seabed.
  bool survey = false;
  SurveyOptions survey_options;
  TargetOptions target;
  ViewSamplingOptions poses;
  // A hand-held trajectory (pauses at trajectory.num_pauses poses sampled
  // as `poses` says, smooth moves between) instead of independent views;
  // its frames replace num_images.
  std::optional<TrajectoryOptions> trajectory;
  // Static textured background plane (camera frame, z = distance).
  bool clutter = false;
  double clutter_distance_m = 3.0;
  uint64_t clutter_seed = 12;
  int clutter_num_shapes = 900;
  ImageFormationOptions render;
  // Partial occlusion: with this probability per image an opaque dark plate
  // between camera and target hides about `fraction` of the target.
  double occlusion_probability = 0;
  double occlusion_fraction = 0.15;

  void Check() const;  // throws OptionError naming the key
};

// Throws InputError naming the file and key.
DatasetConfig ReadDatasetConfig(const std::filesystem::path& path);

}  // namespace portcal
