// `portcal stereo_calibrator`: the relative pose of two cameras (each
// optionally behind its own housing) from frames in which both see the
// target; writes the reports.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/stereo_calibration.h"

namespace portcal {

struct StereoCalibratorOptions {
  std::string database_path;
  std::string output_path;
  int camera1_id = -1, camera2_id = -1;  // -1: the two cameras with observations, by id
  // Frames pair by image file name (the part after the folder, e.g.
  // cam1/img_001.png <-> cam2/img_001.png) or by sorted order.
  std::string pairing = "name";
  // In-air (or housing) calibrations of each camera; without them each
  // camera is first calibrated from its own views (in air only).
  std::string input_calibration1, input_calibration2;
  StereoCalibrationSettings stereo;
  void Check() const;  // throws OptionError naming the option
};

// The stage's summary is the calibration itself.
using StereoCalibratorSummary = StereoCalibrationResult;

StereoCalibratorSummary RunStereoCalibrator(const StereoCalibratorOptions& options,
                                            ProgressSink& progress);

}  // namespace portcal
