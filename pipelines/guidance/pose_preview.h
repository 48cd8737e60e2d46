// Pictures of where the target should be: its outline (edges followed
// through lens and housing, so a distorted camera shows them curved) and
// points, drawn on a frame or on an empty image of the camera's size.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/guidance/next_pose.h"

namespace portcal {

// The outline as a closed polygon of pixels (OpenCV's convention, 0-based
// centres); empty where part of it does not project.
std::vector<cv::Point2f> TargetOutlinePixels(const HousedCamera& camera, const TargetShape& target,
                                             const Rigid3d& cam_from_target);

// Draws the outline (and the points, when `with_points`) in `color` onto a
// BGR image.
void DrawTargetAt(const HousedCamera& camera, const TargetShape& target,
                  const Rigid3d& cam_from_target, const cv::Scalar& color, bool with_points,
                  cv::Mat* bgr);

// An image of the camera's size: the target filled at the pose, and a
// caption.
cv::Mat PosePreview(const HousedCamera& camera, const TargetShape& target,
                    const Rigid3d& cam_from_target, const std::string& caption);

}  // namespace portcal
