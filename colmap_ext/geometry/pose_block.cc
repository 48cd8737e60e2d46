#include "colmap_ext/geometry/pose_block.h"

#include <ceres/product_manifold.h>

namespace portcal {

PoseBlock ToPose(const Rigid3d& rigid) {
  const Eigen::Quaterniond q = rigid.rotation.normalized();
  return {q.x(),
          q.y(),
          q.z(),
          q.w(),
          rigid.translation.x(),
          rigid.translation.y(),
          rigid.translation.z()};
}

Rigid3d FromPose(const PoseBlock& p) {
  return Rigid3d(Eigen::Quaterniond(p[3], p[0], p[1], p[2]).normalized(),
                 Eigen::Vector3d(p[4], p[5], p[6]));
}

ceres::Manifold* PoseManifold() {
  return new ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>();
}

}  // namespace portcal
