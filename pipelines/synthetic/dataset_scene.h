// What a synthetic set's frames show, built from its dataset config: the
// target (or, for a survey, a textured seabed along a planned path, with its
// markers) and the static clutter behind it; and the target views a rig's
// cameras both see.
#pragma once

#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/io/ground_truth.h"
#include "pipelines/synthetic/dataset_config.h"
#include "pipelines/synthetic/scene.h"
#include "pipelines/synthetic/seabed_markers.h"
#include "pipelines/synthetic/target_builder.h"
#include "pipelines/synthetic/view_sampler.h"

namespace portcal {

// The static background: a fronto-parallel textured plane at `distance` in
// the camera-1 frame, one texel per pixel there, covering the view.
struct Clutter {
  std::unique_ptr<SceneObject> object;
  Rigid3d cam_from_clutter;
  Eigen::Vector4d extent;
  double texel = 0;
};

Clutter MakeClutter(const DatasetConfig& config);

// What the frames show: a target (with clutter) or, for a survey, a
// textured seabed along a planned path.
struct Scene {
  BuiltTarget target;
  std::unique_ptr<SeabedObject> seabed;
  SeabedMarkers seabed_markers;  // on the seabed, if the survey has any
  SurveyPath survey;
  std::optional<Clutter> clutter;
};

// The scene of `config` (camera 1 plans a survey's path); the target's
// description into `truth`.
Scene BuildScene(const DatasetConfig& config, const HousedCamera& camera1, GroundTruth* truth);

// A target view camera 1 sees; with a rig, resampled until camera 2 sees
// the target too.
Rigid3d SampleRigView(const DatasetConfig& config, const Scene& scene, const HousedCamera& camera1,
                      const HousedCamera& camera2, const std::vector<Eigen::Vector3d>& check_points,
                      std::mt19937_64* rng);

}  // namespace portcal
