#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/fixed_ray_error.h"
#include "colmap_ext/cost/narrow_reproj_errors.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

template <typename CameraModel, typename Port>
ceres::CostFunction* Create(const ObservationModel& model, CostBlocks blocks,
                            const Eigen::Vector2d& observed, double sigma) {
  if (blocks == CostBlocks::kPosePoint) {
    return PosePointError<CameraModel, Port>::Create(model.intrinsics, model.housing, observed,
                                                     sigma);
  }
  return PosePointIntrinsicsError<CameraModel, Port>::Create(model.housing, observed, sigma);
}

}  // namespace

ceres::CostFunction* CreateFixedRayCost(const Eigen::Vector3d& center,
                                        const Eigen::Vector3d& direction, double focal,
                                        double sigma_px) {
  PORTCAL_CHECK(direction.z() > 0);
  return FixedRayError::Create(center, direction, focal, sigma_px);
}

ceres::CostFunction* CreateFixedReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                                 const Eigen::Vector2d& observed_px,
                                                 double sigma_px) {
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
