#include "pipelines/stages/camera_calibrator.h"

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"

namespace portcal {

void CameraCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  if (!camera_model.empty() && !ExistsCameraModelWithName(camera_model)) {
    throw OptionError("--Calibration.camera_model", camera_model, "one of " + CameraModelNames());
  }
  calibration.Check();
}

CameraCalibratorSummary RunCameraCalibrator(const CameraCalibratorOptions& options, ProgressSink& progress) {
  options.Check();
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.camera_id, options.database_path);
  const std::vector<CalibrationView>& views = target_views.by_camera.at(camera_id);
  Camera camera = *database.ReadCamera(camera_id);
  if (!options.camera_model.empty() && options.camera_model != camera.ModelName()) {
    camera = Camera::FromModelName(options.camera_model, camera.MeanFocalLength(), camera.width,
                                   camera.height);
  }
  LOG(INFO) << "camera_calibrator: camera " << camera_id << " (" << camera.ModelName() << "), "
            << views.size() << " views";
  const CameraCalibrationResult result = CalibrateCamera(views, camera, options.calibration);

  CalibrationReport report;
  report.camera = result.camera;
  report.parameters_std_dev = result.params_std_dev;
  report.overall_rms_px = result.overall_rms_px;
  report.residual_sigma_px = result.residual_sigma_px;
  report.num_points = result.num_points;
  report.views = result.views;
  report.target_description = target_views.target;
  if (options.calibration.estimate_board_warp) {
    report.board_warp = result.board_warp;
    report.board_warp_std_dev = result.board_warp_std_dev;
  }
  WriteCalibrationReport(report, options.output_path);
  LOG(INFO) << "camera_calibrator: RMS " << result.overall_rms_px << " px over " << result.num_points
            << " points -> " << options.output_path;
  return result;
}

}  // namespace portcal
