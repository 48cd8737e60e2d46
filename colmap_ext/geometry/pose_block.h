// A pose as one Ceres parameter block: Eigen's quaternion order (x, y, z, w)
// followed by the translation, so that EigenQuaternionManifold applies.
#pragma once

#include <ceres/manifold.h>

#include <array>

#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

using PoseBlock = std::array<double, 7>;  // quaternion x, y, z, w + translation

PoseBlock ToPose(const Rigid3d& rigid);
Rigid3d FromPose(const PoseBlock& pose);
// Quaternion (Eigen's manifold) x translation; the caller's problem owns it.
ceres::Manifold* PoseManifold();

}  // namespace portcal
