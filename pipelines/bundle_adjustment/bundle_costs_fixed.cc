#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

// Point in the camera frame -> pixel through the port (Port = void: none).
template <typename CameraModel, typename Port, typename T>
bool Project(const T* intrinsics, const T* port, const VectorT<T, 3>& p, T* x, T* y) {
  if constexpr (std::is_void_v<Port>) {
    return CameraModel::ImgFromCam(intrinsics, p.x(), p.y(), p.z(), x, y);
  } else {
    return ImgFromWater<CameraModel, Port, T>(intrinsics, port, p, x, y);
  }
}

template <typename T>
VectorT<T, 3> Transform(const T* cam_from_world, const T* point) {
  const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_world);
  const Eigen::Map<const VectorT<T, 3>> translation(cam_from_world + 4);
  const Eigen::Map<const VectorT<T, 3>> xyz(point);
  return rotation * xyz + translation;
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
bool PixelResidual(const T* intrinsics, const PortConstants<kPort>& port_values, const T* cam_from_world,
                   const T* point, const Eigen::Vector2d& observed, double inv_sigma, T* residual) {
  T port[kPort > 0 ? kPort : 1];
  for (int i = 0; i < kPort; ++i) port[i] = T(port_values.values[i]);
  T x, y;
  if (!Project<CameraModel, Port, T>(intrinsics, port, Transform(cam_from_world, point), &x, &y)) return false;
  residual[0] = (x - observed.x()) * inv_sigma;
  residual[1] = (y - observed.y()) * inv_sigma;
  return true;
}

// Pose and point free; intrinsics and port constant.
template <typename CameraModel, typename Port>
struct PosePointError : AutoDiffFunctor<PosePointError<CameraModel, Port>, 2, 7, 3> {
  PosePointError(const ObservationModel& model, const Eigen::Vector2d& observed, double sigma)
      : observed_(observed), inv_sigma_(1.0 / sigma) {
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics_[i] = model.intrinsics.at(i);
    for (int i = 0; i < PortSize<Port>(); ++i) port_.values[i] = model.housing.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, T* residual) const {
    T intrinsics[CameraModel::kNumParams];
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics[i] = T(intrinsics_[i]);
    return PixelResidual<CameraModel, Port>(intrinsics, port_, cam_from_world, point, observed_, inv_sigma_,
                                            residual);
  }
  Eigen::Vector2d observed_;
  double inv_sigma_;
  double intrinsics_[CameraModel::kNumParams];
  PortConstants<PortSize<Port>()> port_;
};

// Pose, point and intrinsics free; port constant.
template <typename CameraModel, typename Port>
struct PosePointIntrinsicsError
    : AutoDiffFunctor<PosePointIntrinsicsError<CameraModel, Port>, 2, 7, 3, CameraModel::kNumParams> {
  PosePointIntrinsicsError(const ObservationModel& model, const Eigen::Vector2d& observed, double sigma)
      : observed_(observed), inv_sigma_(1.0 / sigma) {
    for (int i = 0; i < PortSize<Port>(); ++i) port_.values[i] = model.housing.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, const T* intrinsics, T* residual) const {
    return PixelResidual<CameraModel, Port>(intrinsics, port_, cam_from_world, point, observed_, inv_sigma_,
                                            residual);
  }
  Eigen::Vector2d observed_;
  double inv_sigma_;
  PortConstants<PortSize<Port>()> port_;
};

template <typename CameraModel, typename Port>
ceres::CostFunction* Create(const ObservationModel& model, CostBlocks blocks, const Eigen::Vector2d& observed,
                            double sigma) {
  if (blocks == CostBlocks::kPosePoint) return PosePointError<CameraModel, Port>::Create(model, observed, sigma);
  return PosePointIntrinsicsError<CameraModel, Port>::Create(model, observed, sigma);
}

struct FixedRayError : AutoDiffFunctor<FixedRayError, 2, 7, 3> {
  FixedRayError(const Eigen::Vector3d& center, const Eigen::Vector3d& direction, double focal, double sigma)
      : center_(center), observed_(direction.head<2>() / direction.z()), scale_(focal / sigma) {}
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point, T* residual) const {
    const VectorT<T, 3> p = Transform(cam_from_world, point) - center_.cast<T>();
    if (!(p.z() > T(0))) return false;
    residual[0] = (p.x() / p.z() - observed_.x()) * scale_;
    residual[1] = (p.y() / p.z() - observed_.y()) * scale_;
    return true;
  }
  Eigen::Vector3d center_;
  Eigen::Vector2d observed_;
  double scale_;
};

}  // namespace

ceres::CostFunction* CreateFixedRayCost(const Eigen::Vector3d& center, const Eigen::Vector3d& direction,
                                        double focal, double sigma_px) {
  PORTCAL_CHECK(direction.z() > 0);
  return FixedRayError::Create(center, direction, focal, sigma_px);
}

ceres::CostFunction* CreateFixedReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                                 const Eigen::Vector2d& observed_px, double sigma_px) {
  PORTCAL_CHECK(blocks != CostBlocks::kAll || !model.HasHousing());
  ceres::CostFunction* cost = nullptr;
  VisitCameraModel(model.camera_model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    if (!model.HasHousing()) {
      cost = Create<CameraModel, void>(model, blocks, observed_px, sigma_px);
      return;
    }
    VisitHousingModel(model.housing_model_id, [&](auto port_tag) {
      cost = Create<CameraModel, decltype(port_tag)>(model, blocks, observed_px, sigma_px);
    });
  });
  return cost;
}

}  // namespace portcal
