// Rectified pairs of a calibrated rig: two virtual pinholes at the two
// camera centres, sharing orientation (x along the baseline, z between the
// two optical axes), focal length, principal row and height, so that a
// point's two images lie on the same row and the disparity is f B / z.
// Behind housings each is the virtual pinhole of its camera (exact at
// the design depth); the error maps say how well rows agree elsewhere.
#pragma once

#include <utility>

#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/undistortion/virtual_pinhole.h"

namespace portcal {

struct RectifyingRotations {
  Eigen::Matrix3d rect_from_cam1 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rect_from_cam2 = Eigen::Matrix3d::Identity();
  double baseline = 0;  // m, camera 2's centre along the rectified x axis
};

// Throws InputError for a zero baseline or one along the cameras' mean
// optical axis (no rectification exists).
RectifyingRotations RectifyingRotationsOf(const Rigid3d& cam2_from_cam1);

// The two rectified pinholes: each fitted as FitVirtualPinhole does at its
// design depth, then given one focal length (the mean), one principal row
// and one height; the widths and principal columns stay each camera's own
// (the framing `options.blank_pixels` asks for), so the disparity of a
// point is x1 - x2 - (cx1 - cx2).
std::pair<VirtualPinhole, VirtualPinhole> FitRectifiedPinholes(
    const HousedCamera& camera1, const HousedCamera& camera2, const RectifyingRotations& rotations,
    double design_depth1, double design_depth2, const FieldOfViewOptions& options);

}  // namespace portcal
