#include "pipelines/stages/housing_calibrator.h"

#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_output.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"

namespace portcal {

void HousingCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (input_calibration.empty()) {
    throw OptionError("--input_calibration", "''", "the in-air calibration.yaml");
  }
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  if (!housing) throw OptionError("--Housing.model", "''", "FLATPORT or DOMEPORT");
  housing->ValidateInput("--Housing.params");
  calibration.Check();
}

HousingCalibratorSummary RunHousingCalibrator(const HousingCalibratorOptions& options, ProgressSink& progress) {
  options.Check();
  const Housing& housing = *options.housing;
  const CalibrationReport in_air = ReadCalibrationReport(options.input_calibration);
  Database database(options.database_path,
                    options.update_database ? Database::OpenMode::kReadWrite : Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.camera_id, options.database_path);
  const std::vector<CalibrationView>& views = target_views.by_camera.at(camera_id);
  const std::optional<Camera> database_camera = database.ReadCamera(camera_id);
  if (database_camera->width != in_air.camera.width || database_camera->height != in_air.camera.height) {
    throw InputError(options.input_calibration + ": calibrated for " + std::to_string(in_air.camera.width) +
                     "x" + std::to_string(in_air.camera.height) + " images, the database's are " +
                     std::to_string(database_camera->width) + "x" + std::to_string(database_camera->height));
  }
  LOG(INFO) << "housing_calibrator: " << housing.ModelName() << ", camera " << in_air.camera.ModelName()
            << " from " << options.input_calibration << ", " << views.size() << " views";
  const HousingCalibrationResult result = CalibrateHousing(views, in_air.camera, housing, options.calibration);

  const CalibrationReport report = ReportOf(result, target_views.target);
  WriteCalibrationOutput(report, options.output_path, options.update_database ? &database : nullptr, camera_id);
  LOG(INFO) << "housing_calibrator: RMS " << result.overall_rms_px << " px -> " << options.output_path;
  return result;
}

}  // namespace portcal
