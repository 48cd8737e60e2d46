#include "pipelines/stages/housing_calibrator.h"

#include <filesystem>
#include <optional>

#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/io/mrcal_optimization_inputs.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "colmap_ext/util/string_utils.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_output.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/crosscheck/mrcal_import.h"
#include "pipelines/report/calibration_html.h"

namespace portcal {

void HousingCalibratorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (input_calibration.empty() && in_air_database_path.empty()) {
    throw OptionError("--input_calibration", "''",
                      "the in-air calibration.yaml, or the in-air views (--in_air_database_path)");
  }
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  CheckOutputFolder("--output_path", output_path);
  if (!housing) throw OptionError("--Housing.model", "''", "one of " + HousingModelNames());
  housing->ValidateInput("--Housing.params");
  calibration.Check();
}

namespace {

void CheckImageSize(const Camera& camera, const Camera& database_camera, const std::string& source,
                    const std::string& database_path) {
  if (database_camera.width != camera.width || database_camera.height != camera.height) {
    throw InputError(source + ": calibrated for " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " images, " + database_path + "'s are " +
                     std::to_string(database_camera.width) + "x" +
                     std::to_string(database_camera.height));
  }
}

// The in-air views of the joint solve and the intrinsics it starts from:
// the given calibration's (its held parameters held), else a camera
// calibration of the in-air views.
InAirViews ReadInAirViews(const HousingCalibratorOptions& options,
                          const std::string& underwater_target, const Camera& underwater_camera,
                          std::optional<CalibrationReport>* start) {
  Database database(options.in_air_database_path, Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.in_air_camera_id,
                                          options.in_air_database_path, "--in_air_camera_id");
  InAirViews in_air;
  in_air.views = target_views.by_camera.at(camera_id);
  in_air.share_board_warp = options.share_board_warp && target_views.target == underwater_target;
  if (options.share_board_warp && !in_air.share_board_warp) {
    LOG(WARNING) << "housing_calibrator: --Calibration.share_board_warp: "
                 << options.in_air_database_path << " shows another target ('"
                 << target_views.target << "'), whose warp is its own";
  }
  const Camera database_camera = *database.ReadCamera(camera_id);
  CheckImageSize(underwater_camera, database_camera, options.in_air_database_path,
                 options.database_path);
  if (start->has_value()) {
    for (size_t i = 0; i < (*start)->parameters_std_dev.size(); ++i) {
      if ((*start)->parameters_std_dev[i] == 0) in_air.fixed_params.push_back(static_cast<int>(i));
    }
  } else {
    Camera initial = database_camera;
    if (underwater_camera.model_id != database_camera.model_id) initial = underwater_camera;
    CameraCalibrationSettings settings;
    settings.estimate_board_warp = options.calibration.estimate_board_warp;
    settings.num_threads = options.calibration.num_threads;
    CalibrationReport report;
    report.camera = CalibrateCamera(in_air.views, initial, settings).camera;
    *start = report;
  }
  LOG(INFO) << "housing_calibrator: " << in_air.views.size() << " in-air views of "
            << options.in_air_database_path
            << (in_air.share_board_warp ? " (the board's warp shared)" : "")
            << ", intrinsics refined jointly";
  return in_air;
}

// The in-air views kept in an mrcal .cameramodel's optimization_inputs
// (mrcal-calibrate-cameras', or camera_calibrator's camera.cameramodel):
// with them the lens is solved jointly, as with --in_air_database_path; a
// .cameramodel carries no covariance, so holding its lens would take it
// as exact. None when the file keeps no solve.
std::optional<InAirViews> InAirViewsOfCameraModel(const std::string& path,
                                                  const std::string& underwater_target,
                                                  bool share_board_warp, const Camera& start) {
  if (std::filesystem::path(path).extension() != ".cameramodel") return std::nullopt;
  const MrcalCameraModelFile file = ReadMrcalCameraModel(path);
  if (file.optimization_inputs_base85.empty()) {
    LOG(WARNING) << "housing_calibrator: " << path
                 << " keeps no optimization_inputs: its intrinsics are held "
                 << "as exact (give the in-air views, --in_air_database_path, for a joint solve)";
    return std::nullopt;
  }
  InAirViews in_air = InAirViewsOfMrcalSolve(ReadMrcalBoardSolve(file, path), start,
                                             underwater_target, path, share_board_warp);
  LOG(INFO) << "housing_calibrator: " << in_air.views.size() << " in-air views from " << path
            << "'s optimization_inputs"
            << (in_air.share_board_warp ? " (the board's warp shared)" : "")
            << ", intrinsics refined jointly";
  return in_air;
}

}  // namespace

HousingCalibratorSummary RunHousingCalibrator(const HousingCalibratorOptions& options,
                                              ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  const Housing& housing = *options.housing;
  std::optional<CalibrationReport> start;
  if (!options.input_calibration.empty()) start = ReadCalibrationReport(options.input_calibration);
  Database database(options.database_path, options.update_database ? Database::OpenMode::kReadWrite
                                                                   : Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.camera_id, options.database_path);
  const std::vector<CalibrationView>& views = target_views.by_camera.at(camera_id);
  const Camera database_camera = *database.ReadCamera(camera_id);
  if (start)
    CheckImageSize(start->camera, database_camera, options.input_calibration,
                   options.database_path);
  std::optional<InAirViews> in_air;
  if (!options.in_air_database_path.empty()) {
    in_air = ReadInAirViews(options, target_views.target, start ? start->camera : database_camera,
                            &start);
  } else {
    in_air = InAirViewsOfCameraModel(options.input_calibration, target_views.target,
                                     options.share_board_warp, start->camera);
  }
  LOG(INFO) << "housing_calibrator: " << housing.ModelName() << ", camera "
            << start->camera.ModelName() << ", " << views.size() << " views";
  // Held intrinsics from a file that carries their covariance: it goes into
  // the housing's standard deviations.
  const Eigen::MatrixXd* lens_covariance =
      !in_air && start->parameters_covariance.size() > 0 ? &start->parameters_covariance : nullptr;
  const HousingCalibrationResult result =
      CalibrateHousing(views, start->camera, housing, options.calibration,
                       in_air ? &*in_air : nullptr, lens_covariance);

  CalibrationReport report = ReportOf(result, target_views.target);
  report.projection_uncertainty = ProjectionUncertaintyOf(report, views);
  report.verdict = JudgeCalibration(report, views);
  WriteCalibrationOutput(
      report, options.output_path, options.update_database ? &database : nullptr, camera_id, [&] {
        WriteHtml(
            CalibrationHtml(report, views, "Housing calibration (" + housing.ModelName() + ")",
                            options.image_path),
            options.output_path);
      });
  LOG(INFO) << "housing_calibrator: RMS " << result.overall_rms_px << " px -> "
            << options.output_path;
  new_output.Keep();
  return result;
}

}  // namespace portcal
