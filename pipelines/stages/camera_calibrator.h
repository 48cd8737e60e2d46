// `portcal camera_calibrator`: intrinsics of one camera of the database from
// the target observations target_extractor stored; writes the reports.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

inline CameraCalibrationSettings WithBoardWarp() {
  CameraCalibrationSettings settings;
  settings.estimate_board_warp = true;
  return settings;
}

struct CameraCalibratorOptions {
  std::string database_path;
  // Directory for calibration.yaml / .txt and camera.cameramodel (mrcal's,
  // with the optimization_inputs of the solve where mrcal can express it).
  std::string output_path;
  int camera_id = -1;  // -1: the only camera with observations
  // The images' folder (target_extractor's --image_path), optional: the
  // report then draws the worst views and every view's thumbnail on them.
  std::string image_path;
  std::string camera_model;  // "" = the database camera's model
  // The board's sag is fitted by default, as mrcal does: printed boards
  // bend, and held flat the sag goes into the intrinsics (the real in-air
  // set: 0.28 mm moves fx by 21 px at an RMS that looks as good). A rigid
  // target (glass, metal) may hold it (estimate_board_warp = false). The
  // report says the sag, whether it is significant, and what holding the
  // board flat would have changed.
  CameraCalibrationSettings calibration = WithBoardWarp();
  // Writes the calibrated intrinsics into the database camera (with a prior
  // focal length), so that the next stage, portcal's or COLMAP's, starts
  // from them.
  bool update_database = false;
  void Check() const;  // throws OptionError naming the option
};

// Throws InputError / NumericalError / DatabaseError. Reads the database
// only, unless update_database (one transaction, committed after the
// reports are written).
// The stage's summary is the calibration itself.
using CameraCalibratorSummary = CameraCalibrationResult;

CameraCalibratorSummary RunCameraCalibrator(const CameraCalibratorOptions& options,
                                            ProgressSink& progress);

}  // namespace portcal
