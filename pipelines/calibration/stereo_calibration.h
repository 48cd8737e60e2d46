// Stereo rig calibration from frames in which both cameras see the same
// target, each camera optionally behind its own housing: the relative pose
// starts at a robust median of the frames' relative poses (geodesic L1
// median of the rotations, Hartley et al., "L1 rotation averaging using the
// Weiszfeld algorithm", CVPR 2011; geometric median of the translations),
// each frame's board in camera 2 as numbered or turned by 180 degrees,
// whichever agrees with the pose most frames offer,
// then a joint adjustment of the target poses, the relative pose and,
// optionally, the intrinsics; standard deviations from the covariance scaled
// by the residual variance.
#pragma once

#include <optional>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/view_pose.h"

namespace portcal {

struct StereoFrame {
  CalibrationView cam1, cam2;  // the same target frame seen by both cameras
};

struct StereoCalibrationSettings {
  bool refine_intrinsics = false;
  int max_num_iterations = 200;
  int num_threads = 2;
  void Check() const;  // throws OptionError
};

struct StereoCalibrationResult {
  Rigid3d cam2_from_cam1;
  Rigid3d median_cam2_from_cam1;                                   // the robust initial value
  Eigen::Vector3d rotation_std_dev_deg = Eigen::Vector3d::Zero();  // about cam2's axes
  Eigen::Vector3d translation_std_dev = Eigen::Vector3d::Zero();   // metres
  Camera camera1, camera2;
  std::vector<double> camera1_std_dev, camera2_std_dev;  // 0 when fixed
  double overall_rms_px = 0;
  double residual_sigma_px = 0;
  int num_points = 0;
  std::vector<CalibratedView> views1, views2;  // per frame
};

StereoCalibrationResult CalibrateStereo(const std::vector<StereoFrame>& frames,
                                        const HousedCamera& camera1, const HousedCamera& camera2,
                                        const StereoCalibrationSettings& settings);

// Geodesic L1 median of rotations and geometric median of translations of
// a set of poses (Weiszfeld iterations).
Rigid3d MedianPose(const std::vector<Rigid3d>& poses);

}  // namespace portcal
