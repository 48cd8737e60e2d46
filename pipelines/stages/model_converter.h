// `portcal model_converter`: COLMAP sparse models between .bin and .txt, with
// the housings.txt sidecar (reads the refractive fork's cameras.txt too); and
// one camera to and from other tools' files: mrcal's .cameramodel (both
// ways), OpenCV's FileStorage YAML and ROS camera_info YAML (export).
#pragma once

#include <string>

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

// Returns a one-line summary of what was converted.
std::string ConvertModel(const ModelConverterOptions& options);

}  // namespace portcal
