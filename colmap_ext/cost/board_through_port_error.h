// A point of a calibration target seen through lens and port (a housing
// calibration): target frame -> camera frame -> port -> lens -> pixel.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/cost/virtual_camera_error.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

// Which error a target point seen through a port is measured by: the
// virtual-camera error (back-projection only, a fast start) or the exact
// reprojection error.
enum class PortErrorKind { kVirtualCamera, kReprojection };

// The error of `observed` for a point at `in_cam` (camera frame, in water).
template <typename CameraModel, typename Port, PortErrorKind kError, typename T>
bool PortPointResidual(const T* intrinsics, const T* port, const Eigen::Vector2d& observed,
                       const VectorT<T, 3>& in_cam, T* residual) {
  if constexpr (kError == PortErrorKind::kVirtualCamera) {
    return VirtualCameraResidual<CameraModel, Port, T>(intrinsics, port, observed, in_cam,
                                                       residual);
  } else {
    T x, y;
    if (!ImgFromWater<CameraModel, Port, T>(intrinsics, port, in_cam, &x, &y)) return false;
    residual[0] = x - observed.x();
    residual[1] = y - observed.y();
    return true;
  }
}

// A fixed target point seen through lens and port. Blocks: cam_from_target
// (7), intrinsics, port (the model's parameters; what is held is the
// manifold's business).
template <typename CameraModel, typename Port, PortErrorKind kError>
struct BoardThroughPortError : AutoDiffFunctor<BoardThroughPortError<CameraModel, Port, kError>, 2,
                                               7, CameraModel::kNumParams, Port::kNumParams> {
  BoardThroughPortError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed)
      : point_(point), observed_(observed) {}

  template <typename T>
  bool operator()(const T* cam_from_target, const T* intrinsics, const T* port, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_target);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_target + 4);
    const VectorT<T, 3> in_cam = rotation * point_.cast<T>() + translation;
    return PortPointResidual<CameraModel, Port, kError, T>(intrinsics, port, observed_, in_cam,
                                                           residual);
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
};

// The same with the board's warp (board_warp.h) as a fourth block: the
// board seen under water is the one seen in air, and sags the same.
template <typename CameraModel, typename Port, PortErrorKind kError>
struct WarpedBoardThroughPortError
    : AutoDiffFunctor<WarpedBoardThroughPortError<CameraModel, Port, kError>, 2, 7,
                      CameraModel::kNumParams, Port::kNumParams, 2> {
  WarpedBoardThroughPortError(const Eigen::Vector3d& point, const Eigen::Vector2d& warp_uv,
                              const Eigen::Vector2d& observed)
      : point_(point), warp_uv_(warp_uv), observed_(observed) {}

  template <typename T>
  bool operator()(const T* cam_from_target, const T* intrinsics, const T* port, const T* warp,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_target);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_target + 4);
    VectorT<T, 3> point = point_.cast<T>();
    point.z() += BoardSag(warp, warp_uv_);
    const VectorT<T, 3> in_cam = rotation * point + translation;
    return PortPointResidual<CameraModel, Port, kError, T>(intrinsics, port, observed_, in_cam,
                                                           residual);
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d warp_uv_;
  Eigen::Vector2d observed_;
};

}  // namespace portcal
