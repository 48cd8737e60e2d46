#include "pipelines/camera_calibrator.h"

#include <map>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"

namespace portcal {

void CameraCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  if (!camera_model.empty() && !ExistsCameraModelWithName(camera_model)) {
    throw OptionError("--Calibration.camera_model", camera_model, "one of " + CameraModelNames());
  }
  calibration.Check();
}

CameraCalibrationResult CalibrateCameraStage(const CameraCalibratorOptions& options) {
  options.Check();
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  std::map<camera_t, std::vector<CalibrationView>> views_by_camera;
  std::string target;
  for (const DatabaseImage& image : database.ReadAllImages()) {
    const auto status = database.ReadTargetDetectionStatus(image.image_id);
    if (!status || !status->found) continue;
    target = status->target;
    CalibrationView view;
    view.image_name = image.name;
    for (const TargetObservation& o : database.ReadTargetObservations(image.image_id)) {
      view.points_in_target.push_back(o.point_in_target);
      view.pixels.push_back(o.xy);
    }
    views_by_camera[image.camera_id].push_back(view);
  }
  if (views_by_camera.empty()) {
    throw InputError(options.database_path + ": no target observations; run target_extractor first");
  }
  camera_t camera_id = static_cast<camera_t>(options.camera_id);
  if (options.camera_id < 0) {
    if (views_by_camera.size() > 1) {
      throw InputError(options.database_path + ": " + std::to_string(views_by_camera.size()) +
                       " cameras have observations; choose one with --camera_id (or extract with "
                       "--ImageReader.single_camera 1)");
    }
    camera_id = views_by_camera.begin()->first;
  }
  const auto views = views_by_camera.find(camera_id);
  if (views == views_by_camera.end()) {
    throw InputError(options.database_path + ": camera " + std::to_string(camera_id) +
                     " has no target observations");
  }
  Camera camera = *database.ReadCamera(camera_id);
  if (!options.camera_model.empty() && options.camera_model != camera.ModelName()) {
    camera = Camera::FromModelName(options.camera_model, camera.MeanFocalLength(), camera.width,
                                   camera.height);
  }
  LOG(INFO) << "camera_calibrator: camera " << camera_id << " (" << camera.ModelName() << "), "
            << views->second.size() << " views";
  const CameraCalibrationResult result = CalibrateCamera(views->second, camera, options.calibration);

  CalibrationReport report;
  report.camera = result.camera;
  report.parameters_std_dev = result.params_std_dev;
  report.overall_rms_px = result.overall_rms_px;
  report.residual_sigma_px = result.residual_sigma_px;
  report.num_points = result.num_points;
  report.views = result.views;
  report.target_description = target;
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
