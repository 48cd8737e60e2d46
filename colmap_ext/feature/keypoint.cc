#include "colmap_ext/feature/keypoint.h"

#include <cmath>

namespace portcal {

FeatureKeypoint FeatureKeypoint::FromScaleOrientation(float x, float y, float scale,
                                                      float orientation) {
  FeatureKeypoint keypoint;
  keypoint.x = x;
  keypoint.y = y;
  const float c = std::cos(orientation), s = std::sin(orientation);
  keypoint.a11 = scale * c;
  keypoint.a12 = -scale * s;
  keypoint.a21 = scale * s;
  keypoint.a22 = scale * c;
  return keypoint;
}

float FeatureKeypoint::ComputeScale() const {
  return 0.5f * (std::sqrt(a11 * a11 + a21 * a21) + std::sqrt(a12 * a12 + a22 * a22));
}

float FeatureKeypoint::ComputeOrientation() const { return std::atan2(a21, a11); }

}  // namespace portcal
