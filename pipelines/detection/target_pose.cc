#include "pipelines/detection/target_pose.h"

#include "colmap_ext/util/error.h"
#include "pipelines/calibration/view_pose.h"

namespace portcal {

std::optional<TargetPose> EstimateTargetPose(const TargetDetection& detection,
                                             const HousedCamera& camera) {
  if (!detection.found || detection.points.size() < 4) return std::nullopt;
  CalibrationView view;
  view.image_name = "frame";
  for (const BoardPoint& point : detection.points) {
    view.points_in_target.push_back(point.point_in_target);
    view.pixels.push_back(point.xy);
  }
  try {
    TargetPose pose;
    // One thread: a frame's points are a few dozen residuals, and a live
    // view detects on the other core.
    pose.cam_from_target = EstimateViewPose(view, camera, 1);
    pose.rms_px = ViewRms(view, camera, pose.cam_from_target);
    return pose;
  } catch (const NumericalError&) {
    return std::nullopt;  // the points fit no pose (a degenerate view)
  }
}

}  // namespace portcal
