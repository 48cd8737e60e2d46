// Cost functions of structure-from-motion observations, for the camera and
// housing models known at run time. Residuals are pixels / sigma.
//
// Ceres' autodiff differentiates every parameter block, constant or not,
// so a block that will not move is better captured as a constant: the
// reprojection error comes in three widths, chosen by what is refined.
//   kPosePoint:           blocks cam_from_world (7), point_in_world (3);
//                         intrinsics and housing are constants.
//   kPosePointIntrinsics: + intrinsics (the camera model's count); the
//                         housing is a constant.
//   kPosePointHousing:    + the housing parameters (port model's count);
//                         the intrinsics are constants. Needs a housing.
//   kAll:                 + the intrinsics and the housing parameters
//                         when there is a housing.
// cam_from_world is quaternion x,y,z,w + translation.
//
// The model dispatch is compiled once, in bundle_costs_*.cc: these are the
// heaviest autodiff instantiations in portcal.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"

namespace portcal {

constexpr int kNoHousing = -1;

enum class CostBlocks { kPosePoint, kPosePointIntrinsics, kPosePointHousing, kAll };

struct ObservationModel {
  int camera_model_id = 0;
  std::vector<double> intrinsics;  // used as constants where not a block
  int housing_model_id = kNoHousing;
  std::vector<double> housing;  // used as a constant where not a block

  bool HasHousing() const { return housing_model_id != kNoHousing; }

  // The camera's (and its housing's) model and current parameters.
  static ObservationModel Of(const HousedCamera& camera) {
    ObservationModel model;
    model.camera_model_id = camera.camera.model_id;
    model.intrinsics = camera.camera.params;
    if (camera.housing) {
      model.housing_model_id = camera.housing->model_id;
      model.housing = camera.housing->params;
    }
    return model;
  }
};

// Exact reprojection error: world point -> camera frame -> through the port
// (if any) -> lens -> pixel.
ceres::CostFunction* CreateReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                            const Eigen::Vector2d& observed_px, double sigma_px);

// Virtual-camera error (Jordt 2016, She 2024), blocks as kAll; needs a
// housing.
ceres::CostFunction* CreateVirtualCameraCost(int camera_model_id, int housing_model_id,
                                             const Eigen::Vector2d& observed_px, double sigma_px);

}  // namespace portcal
