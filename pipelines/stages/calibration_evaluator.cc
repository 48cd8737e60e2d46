#include "pipelines/stages/calibration_evaluator.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "colmap_ext/util/string_utils.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/report/calibration_html.h"

namespace fs = std::filesystem;

namespace portcal {

void CalibrationEvaluatorOptions::Check() const {
  if (database_path.empty())
    throw OptionError("--database_path", "''", "a database with target observations");
  if (input_calibration.empty())
    throw OptionError("--input_calibration", "''", "the calibration.yaml to judge");
  if (output_path.empty())
    throw OptionError("--output_path", "''", "a folder for evaluation.yaml/.txt");
  CheckOutputFolder("--output_path", output_path);
  if (folds != 0 && folds < 2) throw OptionError("--Evaluation.folds", folds, "0 (none) or >= 2");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

namespace {

// The same kind of calibration as the one judged, on some of the views: a
// housing from the report's in-air lens (the report's housing as the
// start), or a lens from the report's as the start (the board as the
// evaluation takes it: the report's warp applied, not fitted again).
CalibrationMethod MethodLike(const CalibrationReport& report, int num_threads) {
  return [report, num_threads](const std::vector<CalibrationView>& views,
                               double* rms_px) -> HousedCamera {
    if (report.housing) {
      HousingCalibrationSettings settings;
      settings.num_threads = num_threads;
      const HousingCalibrationResult result =
          CalibrateHousing(views, report.camera, *report.housing, settings);
      *rms_px = result.overall_rms_px;
      return {result.camera, result.housing};
    }
    CameraCalibrationSettings settings;
    settings.num_threads = num_threads;
    const CameraCalibrationResult result = CalibrateCamera(views, report.camera, settings);
    *rms_px = result.overall_rms_px;
    return {result.camera, std::nullopt};
  };
}

std::string Number(double value) {
  if (!std::isfinite(value)) return ".nan";
  return FormatSignificant(value, 6);
}

void WriteEvaluation(const CalibrationEvaluatorOptions& options, const CalibrationReport& report,
                     const std::vector<CalibrationView>& views, bool sagged,
                     const CalibrationEvaluatorSummary& summary) {
  const HeldOutEvaluation& e = summary.evaluation;
  std::ostringstream yaml, text;
  yaml << "# portcal held-out evaluation of " << options.input_calibration << " on "
       << options.database_path << "\nmodel: " << report.camera.ModelName()
       << "\nhousing: " << (report.housing ? report.housing->ModelName() : "none")
       << "\nrms_px: " << Number(e.rms_px) << "\nnum_points: " << e.num_points
       << "\nsystematic_px: " << Number(e.systematic_px)
       << "\nnoise_floor_px: " << Number(e.noise_floor_px) << "\nviews:\n";
  const CalibrationVerdict verdict =
      JudgeHeldOut(e, report, summary.folds, summary.cross_validation_rms_px);
  text << VerdictText(verdict) << "\n";
  text << "Held-out evaluation: " << options.input_calibration << " (" << report.camera.ModelName()
       << (report.housing ? " + " + report.housing->ModelName() : std::string()) << ") on "
       << options.database_path << "\n\n"
       << std::fixed << std::setprecision(4) << "RMS " << e.rms_px << " px over " << e.num_points
       << " points, each view's pose alone with the calibration fixed\nresidual pattern: mean "
          "residual per cell of a "
          "16 x 9 grid, RMS "
       << e.systematic_px << " px (the cells' own scatter would give about " << e.noise_floor_px
       << " px)\n";
  if (report.board_warp && report.board_warp->norm() > 0 && !sagged) {
    text << "note: the calibration fitted a board warp on another target ('"
         << report.target_description << "'); these views' board is taken flat\n";
  } else if (sagged) {
    text << std::setprecision(3) << "note: the board sags as the calibration fitted it (x "
         << 1000 * report.board_warp->x() << " mm, y " << 1000 * report.board_warp->y()
         << " mm at its centre), in every view and every fold\n"
         << std::setprecision(4);
  }
  text << "\n  view                          rms px  points\n";
  for (const ViewEvaluation& view : e.views) {
    yaml << "  - {image: " << YamlQuoted(view.image_name)
         << ", evaluated: " << (view.evaluated ? "true" : "false")
         << ", rms_px: " << Number(view.evaluated ? view.rms_px : NAN)
         << ", points: " << view.num_points << "}\n";
    text << "  " << std::left << std::setw(28) << view.image_name << std::right << std::setw(8)
         << (view.evaluated ? Number(view.rms_px) : "-") << std::setw(8) << view.num_points
         << (view.evaluated ? "" : "  not evaluated: " + view.why) << "\n";
  }
  if (!summary.folds.empty()) {
    yaml << "cross_validation:\n  rms_px: " << Number(summary.cross_validation_rms_px)
         << "\n  folds:\n";
    text << "\n"
         << summary.folds.size() << "-fold cross-validation (view i in fold i mod K): held-out RMS "
         << summary.cross_validation_rms_px
         << " px\n  fold  train  test  train rms  held-out rms\n";
    for (const FoldEvaluation& f : summary.folds) {
      yaml << "    - {fold: " << f.fold << ", train_views: " << f.num_train
           << ", test_views: " << f.num_test << ", train_rms_px: " << Number(f.train_rms_px)
           << ", test_rms_px: " << Number(f.test_rms_px) << "}\n";
      text << "  " << std::setw(4) << f.fold << std::setw(7) << f.num_train << std::setw(6)
           << f.num_test << std::setw(11) << f.train_rms_px << std::setw(14) << f.test_rms_px
           << "\n";
    }
  }
  const fs::path dir(options.output_path);
  std::error_code error;
  fs::create_directories(dir, error);
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": cannot create the output folder");
  const std::string yaml_text = yaml.str(), text_text = text.str();
  WriteFileAtomically(dir / "evaluation.yaml", false,
                      [&](std::ostream& out) { out << yaml_text << VerdictYaml(verdict); });
  WriteFileAtomically(dir / "evaluation.txt", false, [&](std::ostream& out) { out << text_text; });
  HtmlReport html =
      EvaluationHtml(summary.evaluation, views, {report.camera, report.housing}, text_text);
  html.verdict = HtmlVerdictOf(verdict);
  WriteHtml(html, dir);
}

}  // namespace

CalibrationEvaluatorSummary RunCalibrationEvaluator(const CalibrationEvaluatorOptions& options,
                                                    ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  const CalibrationReport report = ReadCalibrationReport(options.input_calibration);
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  const TargetViews target_views = ReadTargetViews(&database);
  const camera_t camera_id = ChooseCamera(target_views, options.camera_id, options.database_path);
  const Camera database_camera = *database.ReadCamera(camera_id);
  if (database_camera.width != report.camera.width ||
      database_camera.height != report.camera.height) {
    throw InputError(options.input_calibration + ": a " + std::to_string(report.camera.width) +
                     "x" + std::to_string(report.camera.height) + " camera, but camera " +
                     std::to_string(camera_id) + " of " + options.database_path + " is " +
                     std::to_string(database_camera.width) + "x" +
                     std::to_string(database_camera.height));
  }
  // The board as the calibration found it, warped if it fitted a warp;
  // another target (another board) is taken flat.
  const std::vector<CalibrationView>& stored = target_views.by_camera.at(camera_id);
  const bool sagged = report.board_warp && report.board_warp->norm() > 0 &&
                      report.target_description == target_views.target;
  const std::vector<CalibrationView> views =
      sagged ? WithBoardSag(stored, *report.board_warp) : stored;
  CalibrationEvaluatorSummary summary;
  // The evaluation, then each fold's calibration and evaluation.
  progress.Begin("calibration_evaluator", 1 + static_cast<size_t>(options.folds));
  summary.evaluation = EvaluateHeldOut(views, {report.camera, report.housing}, options.num_threads);
  progress.Advance(1);
  if (options.folds > 0) {
    summary.folds = CrossValidate(views, options.folds, MethodLike(report, options.num_threads),
                                  options.num_threads);
    double sum_squares = 0;
    int points = 0;
    for (const FoldEvaluation& fold : summary.folds) {
      sum_squares += fold.test_rms_px * fold.test_rms_px * fold.num_test_points;
      points += fold.num_test_points;
    }
    summary.cross_validation_rms_px = std::sqrt(sum_squares / std::max(1, points));
    progress.Advance(static_cast<size_t>(options.folds));
  }
  progress.End();
  WriteEvaluation(options, report, views, sagged, summary);
  LOG(INFO) << "calibration_evaluator: held-out RMS " << summary.evaluation.rms_px << " px over "
            << summary.evaluation.num_points << " points (pattern "
            << summary.evaluation.systematic_px << " px, the cells' scatter alone ~"
            << summary.evaluation.noise_floor_px << " px)"
            << (summary.folds.empty()
                    ? std::string()
                    : ", cross-validated " + Number(summary.cross_validation_rms_px) + " px")
            << " -> " << options.output_path;
  new_output.Keep();
  return summary;
}

}  // namespace portcal
