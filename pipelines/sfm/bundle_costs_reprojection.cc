// kAll reprojection costs (everything a parameter block).
#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/housing/housing_models.h"
#include "pipelines/sfm/bundle_costs.h"
#include "pipelines/sfm/bundle_costs_fixed.h"

namespace portcal {

ceres::CostFunction* CreateReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                            const Eigen::Vector2d& observed_px, double sigma_px) {
  if (blocks != CostBlocks::kAll || model.housing_model_id == kNoHousing) {
    return CreateFixedReprojectionCost(model, blocks, observed_px, sigma_px);
  }
  ceres::CostFunction* cost = nullptr;
  VisitCameraModel(model.camera_model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(model.housing_model_id, [&](auto port_tag) {
      using Port = decltype(port_tag);
      cost = RefractiveReprojError<CameraModel, Port>::Create(observed_px, sigma_px);
    });
  });
  return cost;
}

}  // namespace portcal
