// The target's pose in one image when the camera (and its housing) is
// known: what a live view shows beside the corners, and what next-pose
// guidance measures coverage with.
#pragma once

#include <optional>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/detection/target_detector.h"

namespace portcal {

struct TargetPose {
  Rigid3d cam_from_target;
  double rms_px = 0;  // the points' reprojection error at that pose
};

// A homography on the rays through the lens, then a pose-only solve through
// lens and housing (view_pose.h). nullopt without a found target, with
// fewer than 4 points, or where no pose fits.
std::optional<TargetPose> EstimateTargetPose(const TargetDetection& detection,
                                             const HousedCamera& camera);

}  // namespace portcal
