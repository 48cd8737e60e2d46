#include "colmap_ext/util/progress.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/stages/calibration_evaluator.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/housing_calibrator.h"
#include "pipelines/stages/stereo_calibrator.h"
#include "pipelines/stages/target_extractor.h"
#include "tools/command_line.h"
#include "tools/commands.h"
#include "tools/option_groups.h"

namespace portcal {

int TargetExtractorCommand(int argc, char** argv) {
  TargetExtractorOptions options;
  CommandLine cli("target_extractor",
                  "Imports the images into the database (like COLMAP's feature_extractor) and "
                  "stores the chessboard corners found in each (sub-pixel, by fitting the "
                  "ideal corner pattern) in portcal_target_observations, with the per-image "
                  "outcome in portcal_target_detections. One transaction; safe to rerun.");
  cli.AddRequired("database_path", &options.database_path, "database (created if missing)");
  cli.AddRequired("image_path", &options.image_path, "directory of images");
  Register(&cli, &options.reader);
  TargetDetectorOptions target = DetectorOptions(options);
  Register(&cli, &target);
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    options.target_type = target.type;
    options.square_size_m = target.square_size_m;
    options.chessboard = target.chessboard;
    options.markers = target.markers;
    StderrProgress progress;
    RunTargetExtractor(options, progress);
  });
}

int CameraCalibratorCommand(int argc, char** argv) {
  CameraCalibratorOptions options;
  std::string fixed;
  CommandLine cli(
      "camera_calibrator",
      "Calibrates a camera's intrinsics (any COLMAP model) from the target "
      "observations in the database: Zhang's closed form, then bundle adjustment "
      "of intrinsics and poses; standard deviations from the covariance scaled by "
      "the residual variance. Writes calibration.yaml, calibration.txt and report.html.");
  cli.AddRequired("database_path", &options.database_path, "database with target observations");
  cli.AddRequired("output_path", &options.output_path, "directory for the reports");
  cli.Add("camera_id", &options.camera_id, "camera to calibrate (-1: the only one)");
  cli.Add("image_path", &options.image_path,
          "the images' folder (target_extractor's), optional: the report draws the worst views and "
          "thumbnails on them");
  cli.Add("Calibration.camera_model", &options.camera_model,
          "model to fit (default: the database's)");
  cli.Add(
      "Calibration.fixed_params", &fixed,
      "parameters to hold, comma separated: names (k2, p1, ...), focal, principal_point, extra");
  cli.Add("Calibration.estimate_board_warp", &options.calibration.estimate_board_warp,
          "fit mrcal's two-parameter board sag (0 | 1)");
  cli.Add("Calibration.drop_outlier_views", &options.calibration.drop_outlier_views,
          "remove views whose RMS exceeds outlier_view_factor x median, and re-solve (0 | 1)");
  cli.Add("Calibration.outlier_view_factor", &options.calibration.outlier_view_factor,
          "outlier threshold on a view's RMS, times the median");
  cli.Add("update_database", &options.update_database,
          "write the calibrated intrinsics into the database camera, for the next stage (0 | 1)");
  cli.Add("num_threads", &options.calibration.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    options.calibration.fixed_params = SplitTokens(fixed, ", ");
    RunCameraCalibrator(options, progress);
  });
}

int CalibrationEvaluatorCommand(int argc, char** argv) {
  CalibrationEvaluatorOptions options;
  CommandLine cli(
      "calibration_evaluator",
      "Judges a calibration (lens, or lens and housing) on the target views of a database, "
      "typically views it was not fitted to: each view's pose estimated alone with the "
      "calibration fixed, per-view and overall RMS, and the residuals' pattern over the image "
      "(the mean residual per cell of a 16 x 9 grid against what noise alone gives). With "
      "--Evaluation.folds K: K-fold cross-validation of the same kind of calibration on these "
      "views. Writes evaluation.yaml, evaluation.txt and report.html (pictures beside it).");
  cli.AddRequired("database_path", &options.database_path,
                  "database with target observations (target_extractor)");
  cli.AddRequired("input_calibration", &options.input_calibration,
                  "calibration.yaml to judge (portcal's or calibmar's; with its housing, if any)");
  cli.AddRequired("output_path", &options.output_path,
                  "folder for evaluation.yaml and evaluation.txt");
  cli.Add("camera_id", &options.camera_id, "camera whose views are used (-1: the only one)");
  cli.Add("Evaluation.folds", &options.folds, "K-fold cross-validation (0: none, else >= 2)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunCalibrationEvaluator(options, progress);
  });
}

int HousingCalibratorCommand(int argc, char** argv) {
  HousingCalibratorOptions options;
  CommandLine cli(
      "housing_calibrator",
      "Calibrates a flat or dome port from the target observations of underwater "
      "views. With the same camera's in-air views (--in_air_database_path, or an mrcal "
      ".cameramodel that keeps its optimization_inputs as --input_calibration) the "
      "intrinsics are refined jointly, so the housing's standard deviations include "
      "their uncertainty; else the in-air intrinsics are given (--input_calibration, "
      "portcal's or calibmar's calibration.yaml: its covariance propagated) and held. The port's "
      "axis and magnitude are initialised from the data; thickness, radius and "
      "indices are the constants of --Housing.params. Writes calibration.yaml/.txt and "
      "report.html.");
  cli.AddRequired("database_path", &options.database_path, "database with target observations");
  cli.Add("input_calibration", &options.input_calibration,
          "in-air calibration.yaml, OpenCV/ROS YAML or .cameramodel (one with optimization_inputs: "
          "joint "
          "solve with its views; with --in_air_database_path: the start, optional)");
  cli.Add("in_air_database_path", &options.in_air_database_path,
          "database with the camera's in-air target observations: joint solve");
  cli.Add("in_air_camera_id", &options.in_air_camera_id,
          "camera of the in-air database (-1: the only one)");
  cli.AddRequired("output_path", &options.output_path, "directory for the reports");
  cli.Add("image_path", &options.image_path,
          "the underwater images' folder, optional: the report draws the worst views and "
          "thumbnails on them");
  cli.AddHousing(&options.housing,
                 "the port to calibrate (required; the parameters: its constants and a "
                 "guess for what is estimated)");
  cli.Add("camera_id", &options.camera_id, "camera (-1: the only one)");
  cli.Add("Calibration.refine_intrinsics", &options.calibration.refine_intrinsics,
          "refine the intrinsics jointly (0 | 1)");
  cli.Add("Calibration.initialize_from_data", &options.calibration.initialize_from_data,
          "initialise the port from the views (0: from --Housing.params)");
  cli.Add("Calibration.estimate_board_warp", &options.calibration.estimate_board_warp,
          "fit the board's sag, the underwater views' and the in-air views' each (0 | 1)");
  cli.Add("Calibration.share_board_warp", &options.share_board_warp,
          "one sag for the in-air and underwater views of the same board (0 | 1; only for one "
          "session)");
  cli.Add("update_database", &options.update_database,
          "write the housing and the intrinsics into the database, for the next stage (0 | 1)");
  cli.Add("num_threads", &options.calibration.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunHousingCalibrator(options, progress);
  });
}

int StereoCalibratorCommand(int argc, char** argv) {
  StereoCalibratorOptions options;
  CommandLine cli(
      "stereo_calibrator",
      "Calibrates the relative pose of two cameras from frames in which both see the "
      "target (robust median of the frames' relative poses, then a joint adjustment), "
      "each camera optionally behind its own housing (from its "
      "--input_calibration). Without input calibrations each camera is first "
      "calibrated in air from its own views. Writes calibration.yaml/.txt and report.html.");
  cli.AddRequired("database_path", &options.database_path,
                  "database with both cameras' observations");
  cli.AddRequired("output_path", &options.output_path, "directory for the reports");
  cli.Add("Stereo.camera1_id", &options.camera1_id, "camera 1 (-1: the lower id of the two)");
  cli.Add("Stereo.camera2_id", &options.camera2_id, "camera 2 (-1: the higher id)");
  cli.Add("Stereo.pairing", &options.pairing, "name (same file name in both folders) | order");
  cli.Add("input_calibration1", &options.input_calibration1, "calibration.yaml of camera 1");
  cli.Add("input_calibration2", &options.input_calibration2, "calibration.yaml of camera 2");
  cli.Add("Stereo.refine_intrinsics", &options.stereo.refine_intrinsics,
          "refine both cameras' intrinsics (0 | 1)");
  cli.Add("num_threads", &options.stereo.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunStereoCalibrator(options, progress);
  });
}

}  // namespace portcal
