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
#include "pipelines/bundle_adjustment/self_calibration.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {

// The schedule's options (ba, marker_scale, the IRLS tolerances, the
// principal point test) are SelfCalibrationOptions'.
struct RefractiveBundleAdjusterOptions : SelfCalibrationOptions {
  std::string input_path;          // sparse model (+ housings.txt)
  std::string output_path;         // adjusted model and reports
  std::string database_path;       // for marker detections (optional)
  std::optional<Housing> housing;  // replaces the model's housings
  // The first guess of the housing, for one case only: the model's own
  // housing lies at a bound of the adjustment (a flat port's distance at its
  // 0.1 mm floor, a dome decentred to 90 % of its radius; the mapper can
  // slide it there). With intrinsics and housing refined, the adjustment
  // then starts its bound parameters (flat: distance; dome: centre) from
  // this guess, the rest (a flat port's normal) from the model, and adjusts
  // the intrinsics first. auto_calibrator passes its --Housing.*.
  std::optional<Housing> housing_guess;
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

RefractiveBundleAdjusterSummary RunRefractiveBundleAdjuster(
    const RefractiveBundleAdjusterOptions& options, ProgressSink& progress);

}  // namespace portcal
