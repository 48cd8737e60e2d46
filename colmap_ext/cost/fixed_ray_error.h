// The virtual-camera error with intrinsics and housing held: the observed
// ray is then a constant, and so is its virtual camera (centre on the
// refraction axis, Jordt 2016), so the residual is a pinhole projection of
// the point seen from `center` compared with the ray's `direction` (both in
// the camera frame), scaled to pixels by `focal` and divided by sigma.
// Blocks: cam_from_world (7), point_in_world (3).
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/point_in_cam.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

struct FixedRayError : AutoDiffFunctor<FixedRayError, 2, 7, 3> {
  FixedRayError(const Eigen::Vector3d& center, const Eigen::Vector3d& direction, double focal,
                double sigma)
      : center_(center), observed_(direction.head<2>() / direction.z()), scale_(focal / sigma) {}
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, T* residual) const {
    const VectorT<T, 3> p = PointInCam(cam_from_world, point) - center_.cast<T>();
    if (!(p.z() > T(0))) return false;
    residual[0] = (p.x() / p.z() - observed_.x()) * scale_;
    residual[1] = (p.y() / p.z() - observed_.y()) * scale_;
    return true;
  }
  Eigen::Vector3d center_;
  Eigen::Vector2d observed_;
  double scale_;
};

}  // namespace portcal
