// Where the target should be held next (Calibration Wizard, Peng & Sturm,
// ICCV 2019, with mrcal's measure): first a fixed opening sequence, then the
// pose whose view most lowers the expected projection uncertainty once added
// to the views kept so far (mrcal's mean-frames measure), searched over poses
// that keep the whole target in view with a margin, within a tilt limit and
// a reachable distance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/guidance/calibration_unknowns.h"
#include "pipelines/guidance/projection_uncertainty.h"

namespace portcal {

struct NextPoseOptions {
  double distance_min_m = 0.3;   // camera centre to target centre: what a person can reach
  double distance_max_m = 1.5;   // >= distance_min_m
  double tilt_max_deg = 50;      // target normal vs line of sight, [0, 80]
  double roll_max_deg = 30;      // about the line of sight, [0, 180]
  double border_margin_px = 20;  // the whole target this far inside the image, >= 0
  int num_candidates = 300;      // poses scored per suggestion, >= 1
  uint64_t seed = 1;
  // Where projection is scored: working_distance_m <= 0 takes the middle
  // of the distance range.
  ProjectionUncertaintyOptions uncertainty;
  void Check() const;  // throws OptionError naming the --Live. option
  ProjectionUncertaintyOptions Uncertainty() const;
};

// The target as guidance sees it: its points and the corners of its
// outline (target frame, z = 0 plane, front towards -z).
struct TargetShape {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> outline;  // the points' bounding rectangle
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  static TargetShape FromPoints(const std::vector<Eigen::Vector3d>& points);
};

struct PoseSuggestion {
  Rigid3d cam_from_target;
  std::string why;  // "opening 2/3: tilted about the horizontal axis", ...
  bool opening = false;
  ProjectionUncertainty before;  // with the kept views
  ProjectionUncertainty after;   // with the suggested view added
};

// The opening sequence: a fronto-parallel view, then views tilted about the
// horizontal and the vertical axes (after Rojtberg & Kuijper, ISMAR 2018:
// focal length and principal point need tilted views before distortion
// repays views near the image's corners). Each at the nearest distance in
// range that keeps the target inside the image.
std::vector<PoseSuggestion> OpeningPoses(const CalibrationUnknowns& unknowns,
                                         const TargetShape& target, const NextPoseOptions& options);

// The next `count` poses: the opening poses not yet taken (`num_kept` views
// kept), then greedily the best candidate, each added to the information
// before the next is chosen. `information`: the kept views' (unit pixel
// variance). Throws NumericalError when no pose keeps
// the target in view within the options.
std::vector<PoseSuggestion> SuggestPoses(const CalibrationUnknowns& unknowns,
                                         const TargetShape& target,
                                         const CalibrationInformation& information, int num_kept,
                                         int count, const NextPoseOptions& options);

// A stereo rig's guidance: both cameras' unknowns and the rig's relative
// pose (its own uncertainty is not scored: the views that fix the two
// cameras' intrinsics also fix it well).
struct RigUnknowns {
  CalibrationUnknowns camera1, camera2;
  Rigid3d cam2_from_cam1;
};

// The next pose of the target for a rig, as camera 1 sees it: while fewer
// than 3 pairs are kept, the opening poses turned about the point between
// the cameras' axes (nearest distance where both see the whole target),
// then the candidate seen whole by both cameras that most lowers the
// larger of the two cameras' expected uncertainty. `before` and `after` are
// the worse camera's. Throws NumericalError when no pose keeps the target
// in both views within the options.
PoseSuggestion SuggestRigPose(const RigUnknowns& rig, const TargetShape& target,
                              const CalibrationInformation& information1,
                              const CalibrationInformation& information2, int num_kept,
                              const NextPoseOptions& options);

// How far the target is from a suggested pose: the mean distance (px) of
// its outline's corners in the image, the rotation (deg) between the poses
// and the distance (m) between the target's centres; the target turned by
// 180 deg about its normal counts as the same.
struct PoseDistance {
  double outline_px = 0;
  double rotation_deg = 0;
  double translation_m = 0;
};
PoseDistance DistanceToSuggestion(const CalibrationUnknowns& unknowns, const TargetShape& target,
                                  const Rigid3d& cam_from_target, const Rigid3d& suggested);

}  // namespace portcal
