// The schedule of a self-calibrating bundle adjustment (housing and,
// optionally, intrinsics refined with the points and poses): iteratively
// reweighted least squares in stages, outliers dropped between a robust and
// a final solve, garbage refused, and the principal point tested against
// the image centre. refractive_bundle_adjuster wraps it with reading the
// model and writing the calibration.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

struct SelfCalibrationOptions {
  BundleAdjustmentOptions ba;  // refine_housing on, exact reprojection error
  MarkerScale marker_scale;
  double max_reproj_error_px = 4.0;  // observations beyond are dropped before the final solve
  // The schedule of iteratively reweighted least squares: the first solve,
  // robust, decides the inliers and their weights, and ends when they have
  // settled (at most robust_max_unsettled_weights of the observations'
  // weights changed by more than 0.01 in a step: weights_settled.h) or at
  // robust_function_tolerance, the relative cost change; the final solve
  // holds the weights (BundleAdjustmentOptions::hold_loss_weights) and runs
  // to ba.function_tolerance. Without held weights both solves are robust
  // to ba.function_tolerance, and on a survey the first crawls (1000
  // images: 43 iterations where the robust cost changes by ~1e-8 each;
  // docs/benchmarks.md). The relative cost change alone ends the robust
  // solve later the longer the survey (4 iterations at 1000 images, 7 at
  // 2000), the weights settle after one (docs/scale.md).
  bool hold_weights = true;
  double robust_function_tolerance = 1e-6;
  double robust_max_unsettled_weights = 0.01;  // 0: the cost change alone
  // The final solve's first trust region (BundleAdjustmentOptions::
  // initial_trust_region_radius). With the weights held it is a weighted
  // least-squares problem started near its minimum, where Gauss-Newton
  // converges in a step; Ceres' default (1e4) damps a survey's weak modes
  // (the long strips' bending) and the solve crawls while the region grows
  // 3 x a step (2000 images: 4 steps against 1; docs/scale.md).
  double held_trust_region_radius = kHeldWeightsTrustRegionRadius;
  // With ba.refine_principal_point and a value > 0: after the final solve the
  // principal point is set to the image centre and held there (the solve
  // redone) unless the refined one lies more than this many standard
  // deviations from the centre in x or y. Refined when the data cannot tell
  // it from the centre, it only trades with a flat port's tilt (1 px ~ 0.04
  // deg at f = 1300 px; shared flat set: normal 0.015 -> 0.048 deg); held at
  // the centre when it is elsewhere, it wrecks the housing (own render with
  // the principal point 5 px off: port distance 3 mm instead of 30 mm).
  double principal_point_test_sigmas = 0;
  SelfCalibrationOptions() {
    ba.refine_housing = true;
    // The virtual-camera error biased the dome's Cz by 1.1 mm on the shared
    // target3d_domeport set (exact error: 0.1 mm); it stays an option.
    ba.virtual_camera_error = false;
    ba.max_num_iterations = 200;
  }
  void Check() const;  // throws OptionError naming the --BundleAdjustment. or --Markers. option
};

// What a self-calibration said besides the model it adjusted.
struct SelfCalibrationOutcome {
  std::vector<std::string> notes;     // the principal point test's
  std::vector<std::string> warnings;  // a principal point the data do not determine
  int num_filtered = 0;               // observations dropped beyond max_reproj_error_px
  bool principal_point_held = false;  // by principal_point_test_sigmas
};

// The adjustment of one model, in stages: with the intrinsics refined too,
// the housing is first adjusted under the mapper's intrinsics (started
// jointly from an untilted guess, the focal length and the port distance
// trade off and the solve can slide into the distance's lower bound with a
// wrong focal length; docs/dev/auto_calibration_notes.md); each solve twice, outliers
// dropped in between; then the principal point test.
class SelfCalibration {
 public:
  // `model_name` names the model in errors; `r` and `markers` are adjusted
  // in place and must outlive this.
  SelfCalibration(const SelfCalibrationOptions& options, std::string model_name, Reconstruction* r,
                  std::vector<MarkerCorner>* markers);

  // Intrinsics and housing both refined.
  bool joint() const { return joint_; }
  // The camera whose housing sits at a bound of the adjustment, if any.
  camera_t HousingAtBound() const;

  // The staged adjustment (the intrinsics alone first when
  // `intrinsics_first`), then the principal point test. Throws
  // NumericalError naming the model when the intrinsics come out implausible.
  SelfCalibrationOutcome Calibrate(bool intrinsics_first, CalibrationStdDevs* std_devs);

 private:
  BundleAdjustmentOptions Robust(const BundleAdjustmentOptions& ba) const;
  void Solve(const BundleAdjustmentOptions& ba, CalibrationStdDevs* std_devs,
             SelfCalibrationOutcome* outcome);
  void WarnIfPrincipalPointPoor(const CalibrationStdDevs& std_devs,
                                SelfCalibrationOutcome* outcome) const;
  std::string TestPrincipalPoint(CalibrationStdDevs* std_devs, SelfCalibrationOutcome* outcome);

  const SelfCalibrationOptions& options_;
  const std::string model_name_;
  Reconstruction& r_;
  std::vector<MarkerCorner>& markers_;
  const std::map<camera_t, HousedCamera> cameras_before_;
  const bool joint_;
};

// Moves the position of every housing at a bound of the adjustment (flat:
// distance; dome: centre) to the guess's, when the guess is of the same
// model; the rest stays.
void MoveHousingsOffBound(const std::optional<Housing>& guess, Reconstruction* r);

}  // namespace portcal
