// A point of a planar calibration target seen in air: target frame ->
// camera frame -> lens -> pixel. The board may sag (mrcal's two-parameter
// parabolic warp), which moves the point along the board's normal.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/board_warp.h"

namespace portcal {

// Reprojection of a (possibly warped) board point, in pixels. Blocks:
// cam_from_target (quaternion x,y,z,w + translation), intrinsics, warp.
template <typename CameraModel>
struct BoardReprojectionError
    : AutoDiffFunctor<BoardReprojectionError<CameraModel>, 2, 7, CameraModel::kNumParams, 2> {
  BoardReprojectionError(const Eigen::Vector3d& point, const Eigen::Vector2d& warp_uv,
                         const Eigen::Vector2d& observed)
      : point_(point), warp_uv_(warp_uv), observed_(observed) {}

  template <typename T>
  bool operator()(const T* cam_from_target, const T* intrinsics, const T* warp, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_target);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(cam_from_target + 4);
    Eigen::Matrix<T, 3, 1> point = point_.cast<T>();
    point.z() += BoardSag(warp, warp_uv_);
    const Eigen::Matrix<T, 3, 1> in_cam = rotation * point + translation;
    T x, y;
    if (!CameraModel::ImgFromCam(intrinsics, in_cam.x(), in_cam.y(), in_cam.z(), &x, &y)) {
      return false;
    }
    residual[0] = x - observed_.x();
    residual[1] = y - observed_.y();
    return true;
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d warp_uv_;
  Eigen::Vector2d observed_;
};

}  // namespace portcal
