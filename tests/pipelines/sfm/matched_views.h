// Synthetic views of a point cloud 0.6-1.0 m away through a camera (and
// housing), every view matched with every other (the inputs the mapper
// reads), keypoints with Gaussian noise: for the starts that read a lens
// from two-view matches.
#pragma once

#include <cstdint>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {
namespace testing {

enum class ViewMotion {
  kOrbit,    // on an arc around the cloud, looking at its centre
  kGeneral,  // turned and moved at random
  kForward,  // straight ahead along the optical axis (tells no focal length)
};

struct MatchedViews {
  SfmInputs inputs;  // camera 1 is `truth`
  HousedCamera truth;
};

MatchedViews MakeMatchedViews(const HousedCamera& truth, int num_images, double sigma_px,
                              uint32_t seed, ViewMotion motion = ViewMotion::kOrbit);

}  // namespace testing
}  // namespace portcal
