// A point of a calibration target seen by one camera of a rig, in air or
// through a port whose parameters are held.
#pragma once

#include <Eigen/Geometry>
#include <type_traits>
#include <vector>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

// A target point of frame f seen by camera k of the rig: X_k = camk_from_cam1
// * cam1_from_target * X, through the lens and, if Port is not void, the
// port (fixed parameters).
template <typename CameraModel, typename Port>
struct RigBoardError
    : AutoDiffFunctor<RigBoardError<CameraModel, Port>, 2, 7, 7, CameraModel::kNumParams> {
  RigBoardError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed,
                const std::vector<double>& port)
      : point_(point), observed_(observed), port_(port) {}

  template <typename T>
  bool operator()(const T* cam1_from_target, const T* camk_from_cam1, const T* intrinsics,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q1(cam1_from_target), qk(camk_from_cam1);
    const Eigen::Map<const VectorT<T, 3>> t1(cam1_from_target + 4), tk(camk_from_cam1 + 4);
    const VectorT<T, 3> in_cam = qk * (q1 * point_.cast<T>() + t1) + tk;
    T x, y;
    if constexpr (std::is_void_v<Port>) {
      if (!CameraModel::ImgFromCam(intrinsics, in_cam.x(), in_cam.y(), in_cam.z(), &x, &y))
        return false;
    } else {
      T port[Port::kNumParams];
      for (int i = 0; i < Port::kNumParams; ++i) port[i] = T(port_[i]);
      if (!ImgFromWater<CameraModel, Port, T>(intrinsics, port, in_cam, &x, &y)) return false;
    }
    residual[0] = x - observed_.x();
    residual[1] = y - observed_.y();
    return true;
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
  std::vector<double> port_;
};

}  // namespace portcal
