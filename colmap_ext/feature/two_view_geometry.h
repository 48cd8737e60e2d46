// Matches between two images and their verified geometry, as COLMAP 3.8
// stores them (matches, two_view_geometries).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct FeatureMatch {
  uint32_t point2D_idx1 = 0;
  uint32_t point2D_idx2 = 0;
};
using FeatureMatches = std::vector<FeatureMatch>;

// Values of two_view_geometries.config, as in COLMAP 3.8.
enum class TwoViewGeometryConfig : int {
  kUndefined = 0,
  kDegenerate = 1,
  kCalibrated = 2,
  kUncalibrated = 3,
  kPlanar = 4,
  kPanoramic = 5,
  kPlanarOrPanoramic = 6,
  kWatermark = 7,
  kMultiple = 8,
};

struct TwoViewGeometry {
  TwoViewGeometryConfig config = TwoViewGeometryConfig::kUndefined;
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Rigid3d cam2_from_cam1;
  FeatureMatches inlier_matches;

  // The same geometry seen from the other image (swapped roles).
  TwoViewGeometry Inverse() const;
};

}  // namespace portcal
