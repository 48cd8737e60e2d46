#include "pipelines/undistortion/stereo_rectification.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {

RectifyingRotations RectifyingRotationsOf(const Rigid3d& cam2_from_cam1) {
  const Eigen::Matrix3d cam1_from_cam2 = cam2_from_cam1.rotation.toRotationMatrix().transpose();
  // Camera 2's centre in camera 1's frame.
  const Eigen::Vector3d centre2 = -(cam1_from_cam2 * cam2_from_cam1.translation);
  if (!(centre2.norm() > 0)) throw InputError("cam2_from_cam1: zero baseline, nothing to rectify");
  const Eigen::Vector3d x = centre2.normalized();
  const Eigen::Vector3d mean_axis =
      Eigen::Vector3d::UnitZ() + cam1_from_cam2 * Eigen::Vector3d::UnitZ();
  Eigen::Vector3d y = mean_axis.cross(x);
  if (!(y.norm() > 1e-6 * mean_axis.norm())) {
    throw InputError(
        "cam2_from_cam1: the baseline runs along the cameras' optical axes; no rectification "
        "exists");
  }
  y.normalize();
  const Eigen::Vector3d z = x.cross(y);
  RectifyingRotations rotations;
  rotations.rect_from_cam1.row(0) = x.transpose();
  rotations.rect_from_cam1.row(1) = y.transpose();
  rotations.rect_from_cam1.row(2) = z.transpose();
  rotations.rect_from_cam2 = rotations.rect_from_cam1 * cam1_from_cam2;
  rotations.baseline = centre2.norm();
  return rotations;
}

namespace {

// A pinhole's focal lengths scaled to `focal` about its principal point.
void ScaleFocal(double focal, Camera* pinhole) {
  std::vector<double>& p = pinhole->params;
  const double sx = focal / p[0], sy = focal / p[1];
  p[0] = p[1] = focal;
  p[2] *= sx;
  p[3] *= sy;
  pinhole->width =
      static_cast<uint64_t>(std::max(1.0, std::round(static_cast<double>(pinhole->width) * sx)));
  pinhole->height =
      static_cast<uint64_t>(std::max(1.0, std::round(static_cast<double>(pinhole->height) * sy)));
}

}  // namespace

std::pair<VirtualPinhole, VirtualPinhole> FitRectifiedPinholes(
    const HousedCamera& camera1, const HousedCamera& camera2, const RectifyingRotations& rotations,
    double design_depth1, double design_depth2, const FieldOfViewOptions& options) {
  VirtualPinhole first =
      FitVirtualPinhole(camera1, design_depth1, rotations.rect_from_cam1, options);
  VirtualPinhole second =
      FitVirtualPinhole(camera2, design_depth2, rotations.rect_from_cam2, options);
  const double focal = 0.25 * (first.pinhole.params[0] + first.pinhole.params[1] +
                               second.pinhole.params[0] + second.pinhole.params[1]);
  ScaleFocal(focal, &first.pinhole);
  ScaleFocal(focal, &second.pinhole);
  // One principal row and height: the rows both images show (blank_pixels
  // 0) or that either shows (1), blended.
  const double b = options.blank_pixels;
  const double above1 = first.pinhole.params[3], above2 = second.pinhole.params[3];
  const double below1 = static_cast<double>(first.pinhole.height) - above1;
  const double below2 = static_cast<double>(second.pinhole.height) - above2;
  const double above = (1 - b) * std::min(above1, above2) + b * std::max(above1, above2);
  const double below = (1 - b) * std::min(below1, below2) + b * std::max(below1, below2);
  for (VirtualPinhole* pinhole : {&first, &second}) {
    pinhole->pinhole.params[3] = above;
    pinhole->pinhole.height = static_cast<uint64_t>(std::max(1.0, std::round(above + below)));
  }
  return {first, second};
}

}  // namespace portcal
