#include "pipelines/stages/cross_check.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <set>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "colmap_ext/util/string_utils.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/crosscheck/disagreement.h"
#include "pipelines/crosscheck/lens_comparison.h"
#include "pipelines/crosscheck/mrcal_calibration.h"
#include "pipelines/report/calibration_html.h"

namespace portcal {
namespace {

// The target views of the calibrated camera that the input calibration
// used (its dropped outlier views stay out); the image size must match.
std::vector<CalibrationView> ViewsOfInput(const CrossCheckOptions& options,
                                          const CalibrationReport& input) {
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.camera_id, options.database_path);
  std::set<std::string> dropped;
  for (const CalibratedView& view : input.views) {
    if (view.dropped) dropped.insert(view.image_name);
  }
  std::vector<CalibrationView> views;
  for (const CalibrationView& view : target_views.by_camera.at(camera_id)) {
    if (!dropped.count(view.image_name)) views.push_back(view);
  }
  if (!dropped.empty()) {
    LOG(INFO) << "cross_check: " << dropped.size()
              << " views dropped by the input calibration left out";
  }
  const Camera db_camera = *database.ReadCamera(camera_id);
  if (db_camera.width != input.camera.width || db_camera.height != input.camera.height) {
    throw InputError(
        options.input_calibration + ": image size " + std::to_string(input.camera.width) + "x" +
        std::to_string(input.camera.height) + " differs from camera " + std::to_string(camera_id) +
        " of " + options.database_path + " (" + std::to_string(db_camera.width) + "x" +
        std::to_string(db_camera.height) + ")");
  }
  return views;
}

// The projection-difference maps the stage wrote, for the page.
std::vector<ReportPicture> DifferenceMaps(const CrossCheckResult& result,
                                          const CrossCheckOptions& options) {
  std::vector<ReportPicture> maps = {
      {"projection_diff.png",
       "How far portcal's and mrcal's calibrations of the same views project the same ray apart, "
       "over the image "
       "(mrcal's projection difference, with its implied transform). Within the noise: they agree.",
       {}}};
  if (result.rerun_diff) {
    maps.push_back({"projection_diff_rerun.png",
                    "The same after portcal re-ran as mrcal did (board warp, outliers).",
                    {}});
  }
  if (options.folds >= 2) {
    maps.push_back(
        {"cross_validation_diff.png",
         "Fold 0 against fold 1, each calibrated on its own views: the difference the data alone "
         "makes.",
         {}});
    if (result.rerun_diff) {
      maps.push_back(
          {"cross_validation_diff_rerun.png", "The same, calibrated as the re-run.", {}});
    }
  }
  return maps;
}

// What the report says before any comparison: the models, the threshold,
// the views and portcal's own fit.
CrossCheckResult ResultHeader(const CrossCheckOptions& options, const CalibrationReport& input,
                              const std::string& lensmodel, int num_views,
                              const CameraCalibrationResult& portcal) {
  CrossCheckResult result;
  result.camera_model = input.camera.ModelName();
  result.mrcal_lensmodel = lensmodel;
  result.max_diff_px = options.max_diff_px;
  result.num_views = num_views;
  result.portcal_rms_px = portcal.overall_rms_px;
  if (input.board_warp) {
    result.portcal_warp = input.board_warp;
    result.portcal_warp_std_dev = input.board_warp_std_dev;
  }
  return result;
}

MrcalCalibrationOptions MrcalOptionsOf(const CrossCheckOptions& options) {
  MrcalCalibrationOptions mrcal_options;
  mrcal_options.estimate_board_warp = options.mrcal_board_warp;
  mrcal_options.reject_outliers = options.mrcal_outlier_rejection;
  mrcal_options.regularization = options.mrcal_regularization;
  return mrcal_options;
}

}  // namespace

void CrossCheckOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (input_calibration.empty())
    throw OptionError("--input_calibration", "''", "a calibration.yaml");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  CheckOutputFolder("--output_path", output_path);
  if (folds == 1 || folds < 0) throw OptionError("--CrossCheck.folds", folds, "0 or >= 2");
  if (!(max_diff_px > 0)) throw OptionError("--CrossCheck.max_diff_px", max_diff_px, "> 0");
  if (gridn_width < 3) throw OptionError("--CrossCheck.gridn_width", gridn_width, ">= 3");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

CrossCheckSummary RunCrossCheck(const CrossCheckOptions& options, ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  const CalibrationReport input = ReadCalibrationReport(options.input_calibration);
  if (input.housing) {
    throw InputError(
        options.input_calibration + ": a calibration behind a " + input.housing->ModelName() +
        " housing; mrcal has no refraction, so cross_check compares in-air intrinsics only (give "
        "camera_calibrator's calibration.yaml of the in-air views)");
  }
  // A model mrcal cannot express stops here, naming the nearest one.
  const std::string lensmodel = MrcalLensModelFor(input.camera.ModelName());

  const std::vector<CalibrationView> views = ViewsOfInput(options, input);
  std::filesystem::create_directories(options.output_path);

  // portcal's solution re-solved from the input (same model, same board
  // model): the poses that seed mrcal and the full covariance, which the
  // report file does not carry.
  CameraCalibrationSettings settings;
  settings.estimate_board_warp = input.board_warp.has_value();
  settings.initialize_from_data = false;
  settings.num_threads = options.num_threads;
  const CameraCalibrationResult portcal = CalibrateCamera(views, input.camera, settings);
  CalibratedLens portcal_lens{input.camera, portcal.params_covariance};

  CrossCheckResult result =
      ResultHeader(options, input, lensmodel, static_cast<int>(views.size()), portcal);
  ProjectionDiffOptions diff_options;
  diff_options.gridn_width = options.gridn_width;
  NoteResolveDifference(input.camera, portcal.camera, diff_options, &result);

  const MrcalCalibrationResult mrcal =
      CalibrateWithMrcal(views, input.camera, Poses(portcal), MrcalOptionsOf(options));
  NoteMrcalSolution(views, mrcal, &result);
  const std::vector<double> portcal_std_dev =
      input.parameters_std_dev.size() == input.camera.params.size() ? input.parameters_std_dev
                                                                    : portcal.params_std_dev;
  result.parameters = CompareParameters(input.camera, portcal_std_dev, mrcal);
  result.diff = ComputeProjectionDiff(portcal_lens, LensOf(mrcal), diff_options);
  result.pass = result.diff.p95_px <= options.max_diff_px;
  const std::filesystem::path dir(options.output_path);
  WriteProjectionDiffHeatMap(result.diff, static_cast<int>(input.camera.width),
                             static_cast<int>(input.camera.height), "portcal vs mrcal",
                             dir / "projection_diff.png");
  WriteMrcalCameraModel(mrcal.camera, Rigid3d(), dir / "mrcal.cameramodel");
  WriteMrcalCameraModel(input.camera, Rigid3d(), dir / "portcal.cameramodel");

  const double max_z = std::accumulate(
      result.parameters.begin(), result.parameters.end(), 0.0,
      [](double m, const ParameterComparison& p) { return std::max(m, std::abs(p.z)); });
  const bool warp_cause = !input.board_warp && options.mrcal_board_warp && WarpSignificant(mrcal);
  const bool outlier_cause = mrcal.num_outliers > 0;
  if (!result.pass || max_z > 3) {
    ExplainDisagreement(input, lensmodel, mrcal, warp_cause, outlier_cause,
                        options.mrcal_regularization, &result);
  }

  CameraCalibrationSettings rerun_settings = settings;
  std::vector<CalibrationView> rerun_views = views;
  if ((!result.pass || max_z > 3) && (warp_cause || outlier_cause)) {
    rerun_views = RerunAsMrcal(views, input.camera, mrcal, outlier_cause, diff_options, dir,
                               &rerun_settings, &result);
  }

  if (options.folds >= 2) {
    result.cross_validations.push_back(CrossValidate(
        views, input.camera, settings, options.folds, options.gridn_width,
        settings.estimate_board_warp ? "as the input (board warp)" : "as the input (flat board)",
        dir / "cross_validation_diff.png"));
    if (result.rerun_diff) {
      result.cross_validations.push_back(CrossValidate(
          rerun_views, input.camera, rerun_settings, options.folds, options.gridn_width,
          "as the re-run", dir / "cross_validation_diff_rerun.png"));
    }
  }
  CalibrationReport portcal_report =
      ReportOf(portcal, settings.estimate_board_warp, input.target_description);
  portcal_report.projection_uncertainty = ProjectionUncertaintyOf(portcal_report, views);
  result.verdict = JudgeCalibration(portcal_report, views);
  AddCrossCheckFindings(result, &*result.verdict);
  portcal_report.verdict = result.verdict;
  const std::string text = WriteCrossCheckReport(result, dir);
  WriteHtml(CrossCheckHtml(portcal_report, views, DifferenceMaps(result, options), text), dir);
  LOG(INFO) << "cross_check: " << result.Verdict();
  new_output.Keep();
  return result;
}

}  // namespace portcal
