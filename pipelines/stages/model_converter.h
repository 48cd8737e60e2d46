// `portcal model_converter`: COLMAP sparse models between .bin and .txt, with
// the housings.txt sidecar (reads the refractive fork's cameras.txt too); and
// one camera to and from other tools' files: mrcal's .cameramodel (both
// ways), OpenCV's FileStorage YAML and ROS camera_info YAML (export).
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"

namespace portcal {

struct ModelConverterOptions {
  // A sparse-model directory, a .cameramodel file or a portcal
  // calibration.yaml.
  std::string input_path;
  // BIN, TXT: a model directory (created; from a single camera: cameras only).
  // CAMERAMODEL, OPENCV_YAML, ROS_YAML: a file.
  std::string output_path;
  std::string output_type = "BIN";
  int camera_id = -1;  // the camera to export from a model (-1: the only one)

  void Check() const;  // throws OptionError naming the option
};

struct ModelConverterSummary {
  std::string description;  // one line: what was converted into what
};

ModelConverterSummary RunModelConverter(const ModelConverterOptions& options,
                                        ProgressSink& progress);

}  // namespace portcal
