// The relative pose of a calibrated pair, refined on the inliers of its
// essential matrix. RANSAC returns the pose of its best minimal sample,
// whose five matches carry their noise into it undiluted
// (docs/benchmarks.md); COLMAP's LO-RANSAC ends on a fit to all inliers.
// Here the fit is Sampson's distance over all inliers, minimised by Ceres
// over the rotation and the translation's direction (the baseline is unit:
// a pair does not observe its scale).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

// Normalised image coordinates (x / z, y / z) of the inlier matches, one
// per pair, and the pose to start from (cam2_from_cam1, |t| = 1). RANSAC's
// inliers include the chance matches that fall within its threshold of
// their epipolar lines, each up to the threshold off where a true match is
// off by the noise: with loss_scale > 0 (normalised units) Sampson's
// distance is under a Cauchy loss of that scale, which takes their pull
// away (0: least squares). Returns the refined pose with |t| = 1, or
// nullopt when there are fewer than 5 matches or the solve fails (the
// caller keeps its start).
std::optional<Rigid3d> RefineRelativePose(const std::vector<Eigen::Vector2d>& points1,
                                          const std::vector<Eigen::Vector2d>& points2,
                                          const Rigid3d& cam2_from_cam1, double loss_scale);

}  // namespace portcal
