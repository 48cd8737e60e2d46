#include "pipelines/stages/camera_calibrator.h"

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_output.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/crosscheck/mrcal_export.h"
#include "pipelines/report/calibration_html.h"

namespace portcal {

void CameraCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  CheckOutputFolder("--output_path", output_path);
  if (!camera_model.empty() && !ExistsCameraModelWithName(camera_model)) {
    throw OptionError("--Calibration.camera_model", camera_model, "one of " + CameraModelNames());
  }
  calibration.Check();
}

CameraCalibratorSummary RunCameraCalibrator(const CameraCalibratorOptions& options,
                                            ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  Database database(options.database_path, options.update_database ? Database::OpenMode::kReadWrite
                                                                   : Database::OpenMode::kReadOnly);
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

  CalibrationReport report =
      ReportOf(result, options.calibration.estimate_board_warp, target_views.target);
  if (options.calibration.estimate_board_warp) {
    CameraCalibrationSettings flat = options.calibration;
    flat.estimate_board_warp = false;
    report.notes.push_back(BoardWarpNote(result, CalibrateCamera(views, camera, flat)));
  }
  report.projection_uncertainty = ProjectionUncertaintyOf(report, views);
  report.verdict = JudgeCalibration(report, views);
  WriteCalibrationOutput(
      report, options.output_path, options.update_database ? &database : nullptr, camera_id, [&] {
        WriteCalibrationCameraModel(views, result, options.calibration, options.output_path);
        WriteHtml(CalibrationHtml(report, views, "Camera calibration", options.image_path),
                  options.output_path);
      });
  LOG(INFO) << "camera_calibrator: RMS " << result.overall_rms_px << " px over "
            << result.num_points << " points -> " << options.output_path;
  new_output.Keep();
  return result;
}

}  // namespace portcal
