// A point of a calibration target seen through lens and port (a housing
// calibration): target frame -> camera frame -> port -> lens -> pixel.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/virtual_camera_error.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

// Which error a target point seen through a port is measured by: the
// virtual-camera error (back-projection only, a fast start) or the exact
// reprojection error.
enum class PortErrorKind { kVirtualCamera, kReprojection };

// A fixed target point seen through lens and port. Blocks: cam_from_target
// (7), intrinsics, port (the model's parameters; what is held is the
// manifold's business).
template <typename CameraModel, typename Port, PortErrorKind kError>
struct BoardThroughPortError
    : AutoDiffFunctor<BoardThroughPortError<CameraModel, Port, kError>, 2, 7,
                      CameraModel::kNumParams, Port::kNumParams> {
  BoardThroughPortError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed)
      : point_(point), observed_(observed) {}

  template <typename T>
  bool operator()(const T* cam_from_target, const T* intrinsics, const T* port, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_target);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_target + 4);
    const VectorT<T, 3> in_cam = rotation * point_.cast<T>() + translation;
    if constexpr (kError == PortErrorKind::kVirtualCamera) {
      return VirtualCameraResidual<CameraModel, Port, T>(intrinsics, port, observed_, in_cam, residual);
    } else {
      T x, y;
      if (!ImgFromWater<CameraModel, Port, T>(intrinsics, port, in_cam, &x, &y)) return false;
      residual[0] = x - observed_.x();
      residual[1] = y - observed_.y();
      return true;
    }
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
};

}  // namespace portcal
