// `portcal synthesize`: renders a calibration image set with exact ground
// truth (images/*.png + ground_truth.yaml in the shared sets' format).
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"

namespace portcal {

struct SynthesizeOptions {
  std::string config_path;  // dataset YAML
  std::string output_path;  // directory (created); images/ and ground_truth.yaml
  int64_t seed = -1;        // overrides the config's seed when >= 0
  int num_threads = 2;      // >= 1
  void Check() const;       // throws OptionError naming the option
};

struct SynthesizeSummary {
  int num_images = 0;      // per camera
  double seconds = 0;      // wall time, rays included
  double ray_seconds = 0;  // computing the cameras' ray maps (once per set)
  double render_seconds_per_image = 0;
};

// Renders into a staging directory and moves the result into place at the
// end: an interrupted run leaves no partial set behind. Throws InputError for
// bad configs (naming the file and key), NumericalError when poses cannot be
// placed, Cancelled when asked to stop.
SynthesizeSummary RunSynthesize(const SynthesizeOptions& options, ProgressSink& progress);

}  // namespace portcal
