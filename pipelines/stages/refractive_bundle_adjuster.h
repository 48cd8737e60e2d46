// `portcal refractive_bundle_adjuster`: bundle adjustment of a sparse model
// that self-calibrates the housing (flat port: normal and distance; dome:
// decentering) and, optionally, the intrinsics, with the exact reprojection
// error (or the virtual-camera error), a robust loss and standard
// deviations from the covariance. With --Markers.side_length and the
// database the markers were detected into, the marker corners join the
// adjustment as points whose distances equal the known side, which fixes the
// scale: the flat-port distance and dome decentering then come out in
// metres. Or, with --PosePrior.position_sigma and the database holding
// position priors (pose_prior_importer), the model is aligned to the priors
// and they join the adjustment: a survey's scale from its navigation.
// Writes the adjusted model and calibration.yaml / .txt.
#pragma once

#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {

struct RefractiveBundleAdjusterOptions {
  std::string input_path;     // sparse model (+ housings.txt)
  std::string output_path;    // adjusted model and reports
  std::string database_path;  // for marker detections (optional)
  std::optional<Housing> housing;  // replaces the model's housings
  // The first guess of the housing, for one case only: the model's own
  // housing lies at a bound of the adjustment (a flat port's distance at its
  // 0.1 mm floor, a dome decentred to 90 % of its radius; the mapper can
  // slide it there). With intrinsics and housing refined, the adjustment
  // then starts its bound parameters (flat: distance; dome: centre) from
  // this guess, the rest (a flat port's normal) from the model, and adjusts
  // the intrinsics first. auto_calibrator passes its --Housing.*.
  std::optional<Housing> housing_guess;
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
  RefractiveBundleAdjusterOptions() {
    ba.refine_housing = true;
    // The virtual-camera error biased the dome's Cz by 1.1 mm on the shared
    // target3d_domeport set (exact error: 0.1 mm); it stays an option.
    ba.virtual_camera_error = false;
    ba.max_num_iterations = 200;
  }
  void Check() const;  // throws OptionError naming the option
};

struct RefractiveBundleAdjusterSummary {
  CalibrationReport report;  // of the first camera
  int num_marker_corners = 0;
  int num_position_priors = 0;  // images whose priors fixed the frame
  int num_filtered = 0;
  bool principal_point_held = false;  // by principal_point_test_sigmas
  // Of report.warnings, those about what the views' geometry cannot tell
  // apart (an intrinsic and a housing parameter traded): another start on
  // the same views cannot cure them.
  int num_geometry_warnings = 0;
};

RefractiveBundleAdjusterSummary RunRefractiveBundleAdjuster(const RefractiveBundleAdjusterOptions& options,
                                                            ProgressSink& progress);

}  // namespace portcal
