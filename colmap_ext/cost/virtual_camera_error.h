// The virtual-camera error of refractive bundle adjustment (Jordt et al.,
// "Refractive 3D reconstruction on underwater images", Methods in
// Oceanography 2016; as modified in She et al., "Refractive COLMAP:
// refractive structure-from-motion revisited", IROS 2024).
//
// The observed pixel is back-projected through lens and port into its ray in
// water. Every ray of an axial camera meets the refraction axis (flat port:
// the line through the camera centre along the normal; dome: the line
// through the camera centre and the sphere centre); a pinhole "virtual
// camera" placed at that meeting point, oriented like the real camera and
// with its mean focal length, sees the ray as a virtual pixel, and the world
// point as another. The residual is their difference divided by sigma. It
// needs back-projection only (closed form), which made it the refractive
// fork's workhorse; RefractiveReprojError is the exact pixel error.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

// The virtual-camera residual (pixels, before division by sigma) of an
// observed pixel and a point in the camera frame. False where the pixel has
// no ray in water or the point is behind the virtual camera.
template <typename CameraModel, typename Port, typename T>
bool VirtualCameraResidual(const T* intrinsics, const T* housing,
                           const Eigen::Vector2d& observed_px, const VectorT<T, 3>& point_in_cam,
                           T* residual) {
  VectorT<T, 3> origin, dir;
  if (!WaterFromImg<CameraModel, Port, T>(intrinsics, housing, T(observed_px.x()),
                                          T(observed_px.y()), &origin, &dir)) {
    return false;
  }
  // Virtual centre: the point of the axis closest to the water ray (they
  // intersect up to rounding). A ray along the axis is not bent: centre 0.
  VectorT<T, 3> center = VectorT<T, 3>::Zero();
  VectorT<T, 3> axis;
  if (Port::RefractionAxis(housing, &axis)) {
    const T cos_axis = axis.dot(dir);
    const T sin2 = T(1) - cos_axis * cos_axis;
    if (sin2 > T(1e-12)) {
      center = ((axis.dot(origin) - cos_axis * dir.dot(origin)) / sin2) * axis;
    }
  }
  const VectorT<T, 3> point_in_virtual = point_in_cam - center;
  if (!(point_in_virtual.z() > T(0)) || !(dir.z() > T(1e-9))) return false;
  const T focal = T(0.5) * (CameraModel::Fx(intrinsics) + CameraModel::Fy(intrinsics));
  residual[0] = focal * (point_in_virtual.x() / point_in_virtual.z() - dir.x() / dir.z());
  residual[1] = focal * (point_in_virtual.y() / point_in_virtual.z() - dir.y() / dir.z());
  return true;
}

template <typename CameraModel, typename Port>
struct VirtualCameraError : AutoDiffFunctor<VirtualCameraError<CameraModel, Port>, 2, 7, 3,
                                            CameraModel::kNumParams, Port::kNumParams> {
  VirtualCameraError(const Eigen::Vector2d& observed_px, double sigma_px)
      : observed_px_(observed_px), inv_sigma_(1.0 / sigma_px) {}

  template <typename T>
  bool operator()(const T* cam_from_world, const T* point_in_world, const T* intrinsics,
                  const T* housing, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_world);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_world + 4);
    const Eigen::Map<const VectorT<T, 3>> point(point_in_world);
    const VectorT<T, 3> point_in_cam = rotation * point + translation;
    if (!VirtualCameraResidual<CameraModel, Port, T>(intrinsics, housing, observed_px_,
                                                     point_in_cam, residual)) {
      return false;
    }
    residual[0] *= inv_sigma_;
    residual[1] *= inv_sigma_;
    return true;
  }

 private:
  Eigen::Vector2d observed_px_;
  double inv_sigma_;
};

}  // namespace portcal
