// The estimate a live calibration shows after each kept view: the camera
// (or the housing, in-air intrinsics given) from the views kept so far, its
// standard deviations, the expected projection uncertainty, and where the
// target should be held next.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/guidance/next_pose.h"

namespace portcal {

struct LiveEstimatorOptions {
  // Camera calibration: the model, image size and starting parameters.
  // Housing calibration: the in-air intrinsics, held.
  Camera camera;
  // Housing calibration when set: the model, its constants and a start.
  std::optional<Housing> housing;
  std::vector<std::string> fixed_params;  // camera calibration
  // The board's sag, fitted as the final calibration (camera_calibrator,
  // housing_calibrator) fits it, so that the answer does not jump at
  // Finish (held flat, the real in-air views' cx moved by 31 px there).
  bool estimate_board_warp = true;
  NextPoseOptions guidance;
  // The corners' noise before a solve has measured it, px.
  double prior_pixel_sigma_px = 0.1;
  int num_threads = 1;
  void Check() const;  // throws OptionError / InputError
  bool HousingCalibration() const { return housing.has_value(); }
  // Views a first solve needs: 3 for intrinsics (Zhang), 2 for a housing.
  int MinViews() const { return HousingCalibration() ? 2 : 3; }
};

// A stereo rig's relative pose from the kept pairs (CalibrateStereo, each
// camera as estimated).
struct LiveRig {
  bool solved = false;
  std::string status;  // why not solved
  Rigid3d cam2_from_cam1;
  Eigen::Vector3d rotation_std_dev_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_std_dev = Eigen::Vector3d::Zero();  // m
  double rms_px = 0;
};

struct LiveEstimate {
  int num_views = 0;
  bool solved = false;             // a calibration of the kept views
  std::string status;              // why not solved, or a warning about the solve
  HousedCamera camera;             // the estimate (the start before a solve)
  std::vector<std::string> names;  // the estimated parameters
  std::vector<double> values;
  std::vector<double> std_devs;  // -1 undetermined
  double rms_px = 0;
  double pixel_sigma_px = 0;           // the residuals' (or the prior)
  std::vector<Rigid3d> view_poses;     // cam_from_target of each kept view
  CalibrationInformation information;  // the kept views', unit pixel variance
  ProjectionUncertainty uncertainty;
  std::optional<PoseSuggestion> next;
  std::string suggestion_error;  // why there is no suggestion
  // A stereo rig (this is camera 1's estimate): camera 2's, whose `next` is
  // the same suggestion as camera 2 sees it, and the relative pose.
  std::shared_ptr<const LiveEstimate> camera2;
  std::optional<LiveRig> rig;

  // "4 views: fx 505.2 ± 0.8, ...; uncertainty 0.41 px (max 1.2 px)"; a
  // rig's: a line per camera and one for the relative pose.
  std::string Summary() const;
  std::string CameraSummary() const;
};

class LiveEstimator {
 public:
  LiveEstimator(const LiveEstimatorOptions& options, const TargetShape& target);

  // Solves the kept views (from the previous estimate's camera), then the
  // information, the uncertainty and the next pose. Never throws for a
  // failed solve: the estimate says why.
  LiveEstimate Estimate(const std::vector<CalibrationView>& views,
                        const LiveEstimate* previous) const;
  // The same without the suggestion.
  LiveEstimate EstimateCamera(const std::vector<CalibrationView>& views,
                              const LiveEstimate* previous) const;

  // How much a view would lower the expected uncertainty (relative, 0..1;
  // 1 while the unknowns are undetermined and the view adds information).
  double Gain(const LiveEstimate& estimate, const CalibrationView& view) const;

  CalibrationUnknowns Unknowns(const HousedCamera& camera) const;
  const TargetShape& target() const { return target_; }
  const NextPoseOptions& guidance() const { return options_.guidance; }
  int num_threads() const { return options_.num_threads; }

 private:
  void Solve(const std::vector<CalibrationView>& views, LiveEstimate* estimate) const;

  LiveEstimatorOptions options_;
  TargetShape target_;
  std::vector<int> fixed_indices_;
};

// A stereo rig's estimate from the kept pairs (views1[i] and views2[i] are
// one frame): each camera's, then the relative pose once both are solved,
// then the rig's next pose (SuggestRigPose; camera 1's opening before the
// relative pose is known).
LiveEstimate EstimateRig(const LiveEstimator& camera1, const LiveEstimator& camera2,
                         const std::vector<CalibrationView>& views1,
                         const std::vector<CalibrationView>& views2, const LiveEstimate* previous);

// How much a kept pair would lower the worse camera's uncertainty: the
// larger of the two cameras' gains.
double RigGain(const LiveEstimator& camera1, const LiveEstimator& camera2,
               const LiveEstimate& estimate, const CalibrationView& view1,
               const CalibrationView& view2);

// The target as guidance sees it: every point the detector options'
// target has.
TargetShape ShapeOfTarget(const TargetDetectorOptions& detector);

}  // namespace portcal
