// The narrower reprojection costs of bundle_costs.h (constants captured),
// compiled in their own unit.
#pragma once

#include "pipelines/bundle_adjustment/bundle_costs.h"

namespace portcal {

// kPosePoint and kPosePointIntrinsics for any housing, and kAll without one.
ceres::CostFunction* CreateFixedReprojectionCost(const ObservationModel& model, CostBlocks blocks,
                                                 const Eigen::Vector2d& observed_px,
                                                 double sigma_px);

}  // namespace portcal

namespace portcal {

// The virtual-camera error with intrinsics and housing held: the observed
// ray is then a constant, and so is its virtual camera (centre on the
// refraction axis, Jordt 2016), so the residual is a pinhole projection --
// the cheap error for registration and local adjustment. `center` and
// `direction` in the camera frame; `focal` scales it to pixels.
ceres::CostFunction* CreateFixedRayCost(const Eigen::Vector3d& center,
                                        const Eigen::Vector3d& direction, double focal,
                                        double sigma_px);

}  // namespace portcal
