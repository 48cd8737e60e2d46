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

#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/refinement/model_refinement.h"

namespace portcal {

struct RefractiveBundleAdjusterOptions : ModelRefinementOptions {
  std::string input_path;     // sparse model (+ housings.txt)
  std::string output_path;    // adjusted model and reports
  std::string database_path;  // for marker detections (optional)
  void Check() const;         // throws OptionError naming the option
};

using RefractiveBundleAdjusterSummary = ModelRefinementSummary;

RefractiveBundleAdjusterSummary RunRefractiveBundleAdjuster(
    const RefractiveBundleAdjusterOptions& options, ProgressSink& progress);

}  // namespace portcal
