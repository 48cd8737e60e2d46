// Reprojection costs with the housing a parameter block (kPosePointHousing,
// kAll).
#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"

namespace portcal {
namespace {

// Pose, point and housing free; intrinsics constant (a port refined under
// known or held intrinsics: 18-wide Jets for RADIAL and FLATPORT where
// kAll's are 23).
template <typename CameraModel, typename Port>
struct PosePointHousingError
    : AutoDiffFunctor<PosePointHousingError<CameraModel, Port>, 2, 7, 3, Port::kNumParams> {
  PosePointHousingError(const std::vector<double>& intrinsics, const Eigen::Vector2d& observed_px, double sigma_px)
      : error_(observed_px, sigma_px) {
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics_[i] = intrinsics.at(i);
  }
  template <typename T>
  bool operator()(const T* cam_from_world, const T* point_in_world, const T* housing, T* residual) const {
    T intrinsics[CameraModel::kNumParams];
    for (int i = 0; i < CameraModel::kNumParams; ++i) intrinsics[i] = T(intrinsics_[i]);
    return error_(cam_from_world, point_in_world, intrinsics, housing, residual);
  }
  RefractiveReprojError<CameraModel, Port> error_;
  double intrinsics_[CameraModel::kNumParams];
};

}  // namespace

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
        cost = PosePointHousingError<CameraModel, Port>::Create(model.intrinsics, observed_px, sigma_px);
      } else {
        cost = RefractiveReprojError<CameraModel, Port>::Create(observed_px, sigma_px);
      }
    });
  });
  return cost;
}

}  // namespace portcal
