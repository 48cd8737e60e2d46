// A world point moved into the camera by a Ceres pose block, for the cost
// functors: cam_from_world is quaternion x,y,z,w + translation.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/housing/port_projection.h"

namespace portcal {

template <typename T>
VectorT<T, 3> PointInCam(const T* cam_from_world, const T* point_in_world) {
  const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_world);
  const Eigen::Map<const VectorT<T, 3>> translation(cam_from_world + 4);
  const Eigen::Map<const VectorT<T, 3>> xyz(point_in_world);
  return rotation * xyz + translation;
}

}  // namespace portcal
