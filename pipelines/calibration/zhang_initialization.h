// Closed-form initialisation of a pinhole camera from views of a planar
// target: Zhang, "A flexible new technique for camera calibration", PAMI
// 2000 (homographies, then the image of the absolute conic with zero skew,
// principal point included, then each view's pose).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct PlanarView {
  std::vector<Eigen::Vector2d> target_xy;  // points on the plane z = 0, metres
  std::vector<Eigen::Vector2d> pixels;     // COLMAP pixels
};

// Normalized DLT homography pixel ~ H [x y 1]; nullopt for < 4 points or a
// degenerate configuration.
std::optional<Eigen::Matrix3d> EstimateHomography(const std::vector<Eigen::Vector2d>& from,
                                                  const std::vector<Eigen::Vector2d>& to);

// Pose of a planar view whose `pixels` are normalized ray coordinates
// (x / z, y / z): the homography's decomposition with K = I, the target in
// front of the camera. nullopt without a homography.
std::optional<Rigid3d> PoseFromNormalizedPlanarView(const PlanarView& view);

struct PinholeEstimate {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<Rigid3d> cam_from_target;  // one per view
};

// Needs >= 3 views in general position (2 with the principal point fixed at
// the image centre, which is what it falls back to). nullopt when the
// conic is not positive definite (views too alike, or too few).
std::optional<PinholeEstimate> InitializePinholeFromPlanarViews(
    const std::vector<PlanarView>& views, int width, int height);

}  // namespace portcal
