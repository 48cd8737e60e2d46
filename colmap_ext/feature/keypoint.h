// A SIFT keypoint and descriptors as COLMAP stores them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace portcal {

// COLMAP's SIFT keypoint: position (COLMAP pixels) and the affine shape
// [a11 a12; a21 a22] (scale and orientation).
struct FeatureKeypoint {
  float x = 0, y = 0;
  float a11 = 1, a12 = 0, a21 = 0, a22 = 1;

  static FeatureKeypoint FromScaleOrientation(float x, float y, float scale, float orientation);
  float ComputeScale() const;
  float ComputeOrientation() const;
};
using FeatureKeypoints = std::vector<FeatureKeypoint>;

// One row per keypoint, 128 uint8 columns (COLMAP's normalisation).
using FeatureDescriptors = Eigen::Matrix<uint8_t, Eigen::Dynamic, 128, Eigen::RowMajor>;

}  // namespace portcal
