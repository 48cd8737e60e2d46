// Reprojection errors with some blocks held: Ceres' autodiff differentiates
// every parameter block, constant or not, so a block that will not move is
// captured as a constant and the Jets stay narrow. Residuals are pixels /
// sigma; false (never zeros) where the point cannot be seen.
//   PosePointError:           cam_from_world (7), point_in_world (3); the
//                             intrinsics and the port are constants.
//   PosePointIntrinsicsError: + intrinsics; the port is a constant.
//   PosePointHousingError:    cam_from_world, point_in_world, housing; the
//                             intrinsics are constants.
// Port = void: no housing (in air).
#pragma once

#include <Eigen/Geometry>
#include <type_traits>
#include <vector>

#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/point_in_cam.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

namespace internal {

// Point in the camera frame -> pixel through the port (Port = void: none).
template <typename CameraModel, typename Port, typename T>
bool Project(const T* intrinsics, const T* port, const VectorT<T, 3>& p, T* x, T* y) {
  if constexpr (std::is_void_v<Port>) {
    return CameraModel::ImgFromCam(intrinsics, p.x(), p.y(), p.z(), x, y);
  } else {
    return ImgFromWater<CameraModel, Port, T>(intrinsics, port, p, x, y);
  }
}

template <int kPort>
struct PortConstants {
  double values[kPort > 0 ? kPort : 1] = {};
};

template <typename Port>
constexpr int PortSize() {
  if constexpr (std::is_void_v<Port>) {
    return 0;
  } else {
    return Port::kNumParams;
  }
}

// The residual of both narrow errors: the port's constants cast to T,
// the point moved into the camera and projected.
template <typename CameraModel, typename Port, typename T, int kPort>
bool PixelResidual(const T* intrinsics, const PortConstants<kPort>& port_values,
                   const T* cam_from_world, const T* point, const Eigen::Vector2d& observed,
                   double inv_sigma, T* residual) {
  T port[kPort > 0 ? kPort : 1];
  for (int i = 0; i < kPort; ++i) port[i] = T(port_values.values[i]);
  T x, y;
  if (!Project<CameraModel, Port, T>(intrinsics, port, PointInCam(cam_from_world, point), &x, &y))
    return false;
  residual[0] = (x - observed.x()) * inv_sigma;
  residual[1] = (y - observed.y()) * inv_sigma;
  return true;
}

}  // namespace internal

// Pose and point free; intrinsics and port constant.
template <typename CameraModel, typename Port>
struct PosePointError : AutoDiffFunctor<PosePointError<CameraModel, Port>, 2, 7, 3> {
  PosePointError(const std::vector<double>& intrinsics, const std::vector<double>& housing,
                 const Eigen::Vector2d& observed, double sigma)
      : observed_(observed), inv_sigma_(1.0 / sigma) {
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics_[i] = intrinsics.at(i);
    for (int i = 0; i < internal::PortSize<Port>(); ++i) port_.values[i] = housing.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, T* residual) const {
    T intrinsics[CameraModel::kNumParams];
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics[i] = T(intrinsics_[i]);
    return internal::PixelResidual<CameraModel, Port>(intrinsics, port_, cam_from_world, point,
                                                      observed_, inv_sigma_, residual);
  }
  Eigen::Vector2d observed_;
  double inv_sigma_;
  double intrinsics_[CameraModel::kNumParams];
  internal::PortConstants<internal::PortSize<Port>()> port_;
};

// Pose, point and intrinsics free; port constant.
template <typename CameraModel, typename Port>
struct PosePointIntrinsicsError : AutoDiffFunctor<PosePointIntrinsicsError<CameraModel, Port>, 2, 7,
                                                  3, CameraModel::kNumParams> {
  PosePointIntrinsicsError(const std::vector<double>& housing, const Eigen::Vector2d& observed,
                           double sigma)
      : observed_(observed), inv_sigma_(1.0 / sigma) {
    for (int i = 0; i < internal::PortSize<Port>(); ++i) port_.values[i] = housing.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, const T* intrinsics, T* residual) const {
    return internal::PixelResidual<CameraModel, Port>(intrinsics, port_, cam_from_world, point,
                                                      observed_, inv_sigma_, residual);
  }
  Eigen::Vector2d observed_;
  double inv_sigma_;
  internal::PortConstants<internal::PortSize<Port>()> port_;
};

// Pose, point and housing free; intrinsics constant (a port refined under
// known or held intrinsics: 18-wide Jets for RADIAL and FLATPORT where
// kAll's are 23).
template <typename CameraModel, typename Port>
struct PosePointHousingError
    : AutoDiffFunctor<PosePointHousingError<CameraModel, Port>, 2, 7, 3, Port::kNumParams> {
  PosePointHousingError(const std::vector<double>& intrinsics, const Eigen::Vector2d& observed_px,
                        double sigma_px)
      : error_(observed_px, sigma_px) {
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics_[i] = intrinsics.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point_in_world, const T* housing,
                  T* residual) const {
    T intrinsics[CameraModel::kNumParams];
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics[i] = T(intrinsics_[i]);
    return error_(cam_from_world, point_in_world, intrinsics, housing, residual);
  }
  RefractiveReprojError<CameraModel, Port> error_;
  double intrinsics_[CameraModel::kNumParams];
};

}  // namespace portcal
