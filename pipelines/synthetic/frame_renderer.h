// Renders a synthetic set's frames: the scene's objects placed for one
// view (and, by chance, an occluder in front of the target), camera 1's
// image and, with a rig, camera 2's, with each camera's ground truth.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <string>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/io/ground_truth.h"
#include "pipelines/synthetic/dataset_config.h"
#include "pipelines/synthetic/dataset_scene.h"
#include "pipelines/synthetic/renderer.h"

namespace portcal {

struct RenderedFrame {
  FrameTruth truth;
  cv::Mat image1, image2;  // image2 with a rig
};

struct FrameRenderer {
  const DatasetConfig& config;
  const Scene& scene;
  const HousedCamera& camera1;
  const HousedCamera& camera2;
  const RayMap& rays1;
  const std::optional<RayMap>& rays2;  // with a rig
  std::string dir1, dir2;              // the images' folders in the set, for the truth's file names

  // Frame `frame`, the image file `name` in each camera's folder. Draws the
  // occluder from `rng`; the noise is seeded by the config's seed and the
  // frame, so a frame renders the same whatever was rendered before.
  RenderedFrame Render(int frame, const std::string& name, const Rigid3d& cam_from_target,
                       const ImageFormationOptions& render, std::mt19937_64* rng) const;
};

}  // namespace portcal
