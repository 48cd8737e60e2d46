// Reprojection error through the exact refractive forward projection: the
// world point is mapped into the camera, traced through the port to the
// pixel it is seen at, and compared with the observation. Residuals are in
// units of sigma (so the cost is chi^2 and robust-loss scales are in sigma).
//
// Parameter blocks: cam_from_world (quaternion x,y,z,w + translation, 7),
// point_in_world (3), intrinsics (CameraModel::kNumParams), housing
// (Port::kNumParams). Returns false (Ceres rejects the step) where the point
// cannot be seen, never zeros.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

template <typename CameraModel, typename Port>
struct RefractiveReprojError : AutoDiffFunctor<RefractiveReprojError<CameraModel, Port>, 2, 7, 3,
                                               CameraModel::kNumParams, Port::kNumParams> {
  RefractiveReprojError(const Eigen::Vector2d& observed_px, double sigma_px)
      : observed_px_(observed_px), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* cam_from_world, const T* point_in_world, const T* intrinsics,
                  const T* housing, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_world);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_world + 4);
    const Eigen::Map<const VectorT<T, 3>> point(point_in_world);
    const VectorT<T, 3> point_in_cam = rotation * point + translation;
    T x, y;
    if (!ImgFromWater<CameraModel, Port, T>(intrinsics, housing, point_in_cam, &x, &y)) {
      return false;
    }
    residual[0] = (x - observed_px_.x()) * inv_sigma_;
    residual[1] = (y - observed_px_.y()) * inv_sigma_;
    return true;
  }

 private:
  Eigen::Vector2d observed_px_;
  double inv_sigma_;
};

}  // namespace portcal
