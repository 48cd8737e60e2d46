// Reprojection costs with the housing a parameter block (kPosePointHousing,
// kAll).
#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/narrow_reproj_errors.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"

namespace portcal {

ceres::CostFunction* CreateReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                            const Eigen::Vector2d& observed_px, double sigma_px) {
  PORTCAL_CHECK_MSG(blocks != CostBlocks::kPosePointHousing || model.HasHousing(),
                    "a housing block without a housing");
  const bool housing_block = blocks == CostBlocks::kAll || blocks == CostBlocks::kPosePointHousing;
  if (!housing_block || !model.HasHousing()) {
    return CreateFixedReprojectionCost(model, blocks, observed_px, sigma_px);
  }
  ceres::CostFunction* cost = nullptr;
  VisitCameraModel(model.camera_model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(model.housing_model_id, [&](auto port_tag) {
      using Port = decltype(port_tag);
      if (blocks == CostBlocks::kPosePointHousing) {
        cost = PosePointHousingError<CameraModel, Port>::Create(model.intrinsics, observed_px,
                                                                sigma_px);
      } else {
        cost = RefractiveReprojError<CameraModel, Port>::Create(observed_px, sigma_px);
      }
    });
  });
  return cost;
}

}  // namespace portcal
