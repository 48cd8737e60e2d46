#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/virtual_camera_error.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"

namespace portcal {

ceres::CostFunction* CreateVirtualCameraCost(int camera_model_id, int housing_model_id,
                                             const Eigen::Vector2d& observed_px, double sigma_px) {
  PORTCAL_CHECK_MSG(housing_model_id != kNoHousing, "the virtual-camera error needs a housing");
  ceres::CostFunction* cost = nullptr;
  VisitCameraModel(camera_model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(housing_model_id, [&](auto port_tag) {
      using Port = decltype(port_tag);
      cost = VirtualCameraError<CameraModel, Port>::Create(observed_px, sigma_px);
    });
  });
  return cost;
}

}  // namespace portcal
