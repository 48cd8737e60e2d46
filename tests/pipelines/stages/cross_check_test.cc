// portcal cross_check: mrcal's solution of the same corners, the projection
// difference (against mrcal's own Python implementation), the difference the
// covariances predict (against Monte Carlo), a warped board caught and
// explained, and the shared sets (rendered: agreement; real: the report).
#include "pipelines/stages/cross_check.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <fstream>
#include <random>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/crosscheck/mrcal_calibration.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr int kBoardW = 12, kBoardH = 9;
constexpr double kSpacing = 0.04;

Camera TruthCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 1000, 1280, 960);
  camera.params = {1000, 1003, 640.3, 479.6, -0.2, 0.08, 0.0008, -0.0005};
  return camera;
}

// Chessboard views from random poses, the board bent by mrcal's parabolic
// sag `warp` (metres) while the stored target points stay flat; Gaussian
// pixel noise `noise_px` per coordinate.
std::vector<CalibrationView> SyntheticViews(const Camera& camera, const Eigen::Vector2d& warp,
                                            double noise_px, int num_views, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, noise_px);
  const Eigen::Vector3d centre((kBoardW - 1) * kSpacing / 2, (kBoardH - 1) * kSpacing / 2, 0);
  std::vector<CalibrationView> views;
  while (static_cast<int>(views.size()) < num_views) {
    const double distance = 0.8 + 0.3 * u(rng);
    const Eigen::Vector3d axis(u(rng), u(rng), 0);
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * u(rng), Eigen::Vector3d::UnitZ())) *
        Eigen::Quaterniond(Eigen::AngleAxisd(0.6 * axis.norm(), axis.normalized()));
    const Eigen::Vector3d position(0.3 * distance * u(rng), 0.25 * distance * u(rng), distance);
    CalibrationView view;
    view.image_name = "view" + std::to_string(views.size()) + ".png";
    for (int j = 0; j < kBoardH; ++j) {
      for (int i = 0; i < kBoardW; ++i) {
        const double ur = 2.0 * i / (kBoardW - 1) - 1, vr = 2.0 * j / (kBoardH - 1) - 1;
        const Eigen::Vector3d flat(i * kSpacing, j * kSpacing, 0);
        const Eigen::Vector3d bent =
            flat + Eigen::Vector3d(0, 0, warp.x() * (1 - ur * ur) + warp.y() * (1 - vr * vr));
        const auto pixel = camera.ImgFromCam(rotation * (bent - centre) + position);
        if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > camera.width ||
            pixel->y() > camera.height) {
          continue;
        }
        view.points_in_target.push_back(flat);
        view.pixels.push_back(*pixel + Eigen::Vector2d(noise(rng), noise(rng)));
      }
    }
    if (view.pixels.size() >= 60) views.push_back(view);
  }
  return views;
}

void WriteDatabase(const fs::path& path, const Camera& camera,
                   const std::vector<CalibrationView>& views) {
  Database db(path, Database::OpenMode::kCreate);
  const camera_t camera_id = db.WriteCamera(camera);
  for (const CalibrationView& view : views) {
    DatabaseImage image;
    image.name = view.image_name;
    image.camera_id = camera_id;
    const image_t image_id = db.WriteImage(image);
    std::vector<TargetObservation> rows;
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      TargetObservation o;
      o.point_id = static_cast<int64_t>(i);
      o.xy = view.pixels[i];
      o.point_in_target = view.points_in_target[i];
      rows.push_back(o);
    }
    db.WriteTargetObservations(image_id, rows);
    TargetDetectionStatus status;
    status.target = "chessboard 12x9";
    status.found = true;
    status.num_points = static_cast<int>(rows.size());
    db.WriteTargetDetectionStatus(image_id, status);
  }
}

// Stores the views, calibrates them with portcal's camera_calibrator (flat
// board) and returns cross_check options on the result.
CrossCheckOptions CalibratedForCheck(const fs::path& dir, const std::vector<CalibrationView>& views,
                                     bool drop_outlier_views = false) {
  WriteDatabase(dir / "db.db", TruthCamera(), views);
  CameraCalibratorOptions calibrate;
  calibrate.database_path = (dir / "db.db").string();
  calibrate.output_path = (dir / "cal").string();
  calibrate.calibration.drop_outlier_views = drop_outlier_views;
  calibrate.calibration.estimate_board_warp = false;
  RunCameraCalibrator(calibrate, NoProgress());
  CrossCheckOptions options;
  options.database_path = calibrate.database_path;
  options.input_calibration = (dir / "cal/calibration.yaml").string();
  options.output_path = (dir / "check").string();
  return options;
}

std::vector<Rigid3d> Poses(const CameraCalibrationResult& result) {
  std::vector<Rigid3d> poses;
  for (const CalibratedView& v : result.views) poses.push_back(v.cam_from_target);
  return poses;
}

// Runs `script` with Debian's Python (where mrcal imports); stdout only.
testing::CommandResult RunPython(const fs::path& dir, const std::string& script) {
  std::ofstream(dir / "script.py") << script;
  return testing::RunCommand("/usr/bin/python3 " + (dir / "script.py").string() + " 2>/dev/null");
}

// Same corners, flat board, 0.1 px noise: the two solvers' lenses agree far
// below the 0.05 px the issue asks, and mrcal's own estimate is within its
// standard deviations of the truth (its warp within them of zero).
TEST(CrossCheck, MrcalAndPortcalAgreeOnAFlatBoard) {
  const Camera truth = TruthCamera();
  const auto views = SyntheticViews(truth, Eigen::Vector2d::Zero(), 0.1, 20, 1);
  const CameraCalibrationResult portcal =
      CalibrateCamera(views, Camera::FromModelName("OPENCV", 900, 1280, 960), {});
  const MrcalCalibrationResult mrcal =
      CalibrateWithMrcal(views, portcal.camera, Poses(portcal), {});
  EXPECT_EQ(mrcal.lensmodel, "LENSMODEL_OPENCV4");
  for (int i = 0; i < 6; ++i) {
    EXPECT_LT(std::abs(mrcal.camera.params[i] - truth.params[i]), 4 * mrcal.params_std_dev[i]) << i;
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(mrcal.board_warp_std_dev[i], 0);
    EXPECT_LT(std::abs(mrcal.board_warp[i]), 4 * mrcal.board_warp_std_dev[i]);
  }
  EXPECT_NEAR(mrcal.residual_sigma_px, 0.1, 0.015);
  const ProjectionDiff diff = ComputeProjectionDiff({portcal.camera, portcal.params_covariance},
                                                    {mrcal.camera, mrcal.params_covariance}, {});
  EXPECT_LT(diff.mean_px, 0.05);
  // Same data: the two agree much better than independent fits would.
  EXPECT_LT(diff.mean_px, diff.predicted_mean_px);
}

// The difference two independent calibrations show, sampled from their
// covariances, against the first-order prediction (fit included).
TEST(CrossCheck, PredictedDifferenceMatchesMonteCarlo) {
  const Camera truth = TruthCamera();
  const auto views = SyntheticViews(truth, Eigen::Vector2d::Zero(), 0.3, 8, 2);
  const CameraCalibrationResult fit =
      CalibrateCamera(views, Camera::FromModelName("OPENCV", 900, 1280, 960), {});
  const Eigen::MatrixXd& c = fit.params_covariance;
  ProjectionDiffOptions options;
  options.gridn_width = 16;
  const ProjectionDiff predicted = ComputeProjectionDiff({fit.camera, c}, {fit.camera, c}, options);
  ASSERT_GT(predicted.predicted_mean_px, 0);

  const Eigen::MatrixXd l = Eigen::LLT<Eigen::MatrixXd>(c).matrixL();
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const auto sample = [&] {
    Eigen::VectorXd z(c.rows());
    for (int i = 0; i < z.size(); ++i) z[i] = normal(rng);
    const Eigen::VectorXd delta = l * z;
    Camera camera = fit.camera;
    for (int i = 0; i < delta.size(); ++i) camera.params[i] += delta[i];
    return camera;
  };
  const int num_samples = 300;
  std::vector<double> sum_squares(predicted.diff_px.size(), 0.0);
  for (int s = 0; s < num_samples; ++s) {
    // Weights from the same covariances as the prediction.
    const ProjectionDiff d = ComputeProjectionDiff({sample(), c}, {sample(), c}, options);
    for (size_t k = 0; k < d.diff_px.size(); ++k) sum_squares[k] += d.diff_px[k] * d.diff_px[k];
  }
  double empirical_mean = 0;
  for (const double ss : sum_squares) empirical_mean += std::sqrt(ss / num_samples);
  empirical_mean /= sum_squares.size();
  // 300 samples: ~4 % Monte-Carlo scatter; 15 % allows for it and the
  // linearisation.
  EXPECT_NEAR(empirical_mean / predicted.predicted_mean_px, 1.0, 0.15)
      << "empirical " << empirical_mean << " px, predicted " << predicted.predicted_mean_px
      << " px";
}

// mrcal's Python projection_diff (focus region, no uncertainties) on the
// same two .cameramodel files.
TEST(CrossCheck, ProjectionDiffEqualsMrcalsPython) {
  if (testing::RunCommand("/usr/bin/python3 -c 'import mrcal' 2>&1").exit_code != 0) {
    GTEST_SKIP() << "mrcal's Python module is not importable by /usr/bin/python3";
  }
  testing::TempDir dir;
  const Camera a = TruthCamera();
  Camera b = a;
  b.params[0] += 4;
  b.params[2] += 3;
  b.params[4] += 0.01;
  b.params[6] += 0.0005;
  WriteMrcalCameraModel(a, Rigid3d(), dir / "a.cameramodel");
  WriteMrcalCameraModel(b, Rigid3d(), dir / "b.cameramodel");
  const auto run = RunPython(dir.path(),
                             "import mrcal, numpy as np\n"
                             "m = [mrcal.cameramodel('" +
                                 (dir / "a.cameramodel").string() + "'), mrcal.cameramodel('" +
                                 (dir / "b.cameramodel").string() +
                                 "')]\n"
                                 "d = mrcal.projection_diff(m, use_uncertainties=False)[0]\n"
                                 "print('%.9f %.9f' % (np.mean(d), np.max(d)))\n");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::istringstream in(run.output);
  double mrcal_mean = 0, mrcal_max = 0;
  in >> mrcal_mean >> mrcal_max;
  const ProjectionDiff ours = ComputeProjectionDiff({a, {}}, {b, {}}, {});
  EXPECT_GT(mrcal_mean, 0.1);  // a real difference to compare
  EXPECT_NEAR(ours.mean_px, mrcal_mean, 1e-4 * mrcal_mean);
  EXPECT_NEAR(ours.max_px, mrcal_max, 1e-4 * mrcal_max)
      << "mean " << ours.mean_px << " vs " << mrcal_mean;
}

// What mrcal's Python makes of camera.cameramodel's optimization_inputs:
// the RMS of its own residuals, its standard deviations of the intrinsics
// (s^2 (J^T J)^-1, s^2 over the degrees of freedom), and how far its
// Gauss-Newton step would move each intrinsic, in those standard deviations.
struct MrcalEvaluation {
  bool has_inputs = false;
  double rms_px = 0;
  std::vector<double> std_devs;
  double max_step_sigma = 0;
};

MrcalEvaluation EvaluateWithMrcal(const fs::path& model, const fs::path& dir) {
  const std::string script =
      "import mrcal, numpy as np\n"
      "m = mrcal.cameramodel('" +
      model.string() +
      "')\n"
      "oi = m.optimization_inputs()\n"
      "if oi is None: print(0); raise SystemExit\n"
      "b, x, J, f = mrcal.optimizer_callback(**oi)\n"
      "J = J.toarray()\n"
      "w = oi['observations_board'][..., 2].ravel()\n"
      "r = x[:2 * w.size].reshape(-1, 2)[w > 0]\n"
      "s2 = (r ** 2).sum() / (2 * len(r) - J.shape[1])\n"
      "D = np.ones(J.shape[1]); mrcal.unpack_state(D, **oi)\n"
      "inv = np.linalg.inv(J.T @ J)\n"
      "i0 = mrcal.state_index_intrinsics(0, **oi); n = oi['intrinsics'].shape[1]\n"
      "sd = np.sqrt(np.diag(inv) * s2)[i0:i0 + n]\n"
      "step = -(inv @ (J.T @ x))[i0:i0 + n]\n"
      "print(1, np.sqrt((r ** 2).sum() / len(r)), np.max(np.abs(step) / sd), ' '.join(str(v) for v "
      "in sd * D[i0:i0 + n]))\n";
  const auto run = RunPython(dir, script);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  std::istringstream in(run.output);
  MrcalEvaluation evaluation;
  in >> evaluation.has_inputs;
  if (!evaluation.has_inputs) return evaluation;
  in >> evaluation.rms_px >> evaluation.max_step_sigma;
  double v = 0;
  while (in >> v) evaluation.std_devs.push_back(v);
  return evaluation;
}

// camera_calibrator's camera.cameramodel carries the solve (corners, poses,
// the warp, partial views): mrcal's own evaluation of it reproduces
// portcal's RMS and standard deviations, finds it at the optimum of its
// cost, and mrcal's C parser still reads the file.
TEST(MrcalExport, OptimizationInputsReproducePortcalsSolution) {
  if (testing::RunCommand("/usr/bin/python3 -c 'import mrcal' 2>&1").exit_code != 0) {
    GTEST_SKIP() << "mrcal's Python module is not importable by /usr/bin/python3";
  }
  testing::TempDir dir;
  const auto views = SyntheticViews(TruthCamera(), Eigen::Vector2d(-0.0003, 0.0005), 0.2, 12, 9);
  CrossCheckOptions check = CalibratedForCheck(dir.path(), views);
  CameraCalibratorOptions calibrate;  // the defaults: the warp fitted
  calibrate.database_path = check.database_path;
  calibrate.output_path = (dir / "warp").string();
  const CameraCalibrationResult result = RunCameraCalibrator(calibrate, NoProgress());
  size_t num_partial = 0;
  for (const CalibrationView& view : views) num_partial += view.pixels.size() < kBoardW * kBoardH;
  ASSERT_GT(num_partial, 0u) << "the views should include boards cut by the image edge";

  const MrcalEvaluation mrcal = EvaluateWithMrcal(dir / "warp/camera.cameramodel", dir.path());
  ASSERT_TRUE(mrcal.has_inputs);
  EXPECT_NEAR(mrcal.rms_px, result.overall_rms_px, 1e-9 * result.overall_rms_px);
  // Same model (OPENCV = LENSMODEL_OPENCV4), same residuals: the same
  // covariance, to the precision of the two Jacobians.
  ASSERT_EQ(mrcal.std_devs.size(), result.params_std_dev.size());
  for (size_t i = 0; i < mrcal.std_devs.size(); ++i) {
    EXPECT_NEAR(mrcal.std_devs[i], result.params_std_dev[i], 1e-3 * result.params_std_dev[i]) << i;
  }
  EXPECT_LT(mrcal.max_step_sigma, 0.01);
  EXPECT_EQ(ReadMrcalCameraModel(dir / "warp/camera.cameramodel").camera.ModelName(), "OPENCV");

  // A held set mrcal cannot hold (k2 alone): the model, without the inputs.
  calibrate.output_path = (dir / "held").string();
  calibrate.calibration.fixed_params = {"k2"};
  RunCameraCalibrator(calibrate, NoProgress());
  EXPECT_FALSE(EvaluateWithMrcal(dir / "held/camera.cameramodel", dir.path()).has_inputs);
}

// A board bent by 0.5 mm, calibrated as flat: cross_check fails, blames the
// warp, and portcal re-run with the warp agrees with mrcal again.
TEST(CrossCheck, WarpedBoardIsCaughtAndExplained) {
  testing::TempDir dir;
  const Camera truth = TruthCamera();
  const Eigen::Vector2d warp(0.0, 0.5e-3);
  CrossCheckOptions options =
      CalibratedForCheck(dir.path(), SyntheticViews(truth, warp, 0.1, 18, 4));
  options.folds = 2;
  const CrossCheckResult result = RunCrossCheck(options, NoProgress());
  EXPECT_FALSE(result.pass) << result.Verdict();
  ASSERT_FALSE(result.causes.empty());
  EXPECT_EQ(result.causes.front().rfind("board warp", 0), 0u) << result.causes.front();
  EXPECT_LT(std::abs(result.mrcal_warp.y() - warp.y()), 4 * result.mrcal_warp_std_dev.y());
  ASSERT_TRUE(result.rerun_diff.has_value());
  EXPECT_LT(result.rerun_diff->mean_px, 0.05);
  EXPECT_EQ(result.Verdict().rfind("FAIL", 0), 0u);
  EXPECT_NE(result.Verdict().find("agree"), std::string::npos);
  // Cross-validated as the input (flat) and as the re-run (warp). A warp
  // biases every fold alike, so cross-validation alone need not see it (here
  // the flat folds stay within 2x); the re-run's folds are consistent.
  ASSERT_EQ(result.cross_validations.size(), 2u);
  EXPECT_GT(result.cross_validations[0].worst_ratio, 0.0);
  EXPECT_LT(result.cross_validations[1].worst_ratio, 2.0);
  for (const char* file :
       {"cross_check.txt", "cross_check.yaml", "projection_diff.png", "projection_diff_rerun.png",
        "cross_validation_diff.png", "mrcal.cameramodel"}) {
    EXPECT_TRUE(fs::exists(dir / "check" / file)) << file;
  }
  const std::string text = testing::ReadFileToString(dir / "check/cross_check.txt");
  EXPECT_EQ(text.substr(text.rfind('\n', text.size() - 2) + 1), result.Verdict() + "\n");
  // mrcal's solution re-imported: the report's file is what mrcal reads.
  EXPECT_EQ(ReadMrcalCameraModel(dir / "check/mrcal.cameramodel").camera.ModelName(), "OPENCV");
}

// Views the input calibration dropped as outliers stay out of the check, so
// portcal's re-solve is the input's solution and the two agree.
TEST(CrossCheck, ViewsDroppedByTheInputStayOut) {
  testing::TempDir dir;
  const Camera truth = TruthCamera();
  std::vector<CalibrationView> views = SyntheticViews(truth, Eigen::Vector2d::Zero(), 0.1, 12, 6);
  std::mt19937 rng(8);
  std::normal_distribution<double> blur(0, 3.0);
  for (Eigen::Vector2d& pixel : views[4].pixels) pixel += Eigen::Vector2d(blur(rng), blur(rng));
  const CrossCheckResult result =
      RunCrossCheck(CalibratedForCheck(dir.path(), views, true), NoProgress());
  EXPECT_EQ(result.num_views, 11);
  EXPECT_TRUE(result.pass) << result.Verdict();
  EXPECT_TRUE(result.causes.empty()) << result.causes.front();
}

TEST(CrossCheck, BadOptionsAndModelsAreNamed) {
  testing::TempDir dir;
  const Camera truth = TruthCamera();
  CrossCheckOptions options =
      CalibratedForCheck(dir.path(), SyntheticViews(truth, Eigen::Vector2d::Zero(), 0.1, 5, 5));
  options.folds = 1;
  EXPECT_THROW(RunCrossCheck(options, NoProgress()), OptionError);
  options.folds = 3;  // 5 views: folds of 2
  try {
    RunCrossCheck(options, NoProgress());
    FAIL() << "3 folds of 5 views must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--CrossCheck.folds"), std::string::npos) << e.what();
  }
  CalibrationReport fisheye;
  fisheye.camera = Camera::FromModelName("OPENCV_FISHEYE", 1000, 1280, 960);
  WriteCalibrationReport(fisheye, dir / "fisheye");
  options.folds = 0;
  options.input_calibration = (dir / "fisheye/calibration.yaml").string();
  try {
    RunCrossCheck(options, NoProgress());
    FAIL() << "OPENCV_FISHEYE must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nearest"), std::string::npos) << e.what();
  }
}

CrossCheckResult CheckSharedSet(const fs::path& images, const std::string& model, int cols,
                                int rows, double square, const fs::path& dir, int folds) {
  TargetExtractorOptions extract;
  extract.database_path = (dir / "db.db").string();
  extract.image_path = images.string();
  extract.reader.camera_model = model;
  extract.reader.single_camera = true;
  extract.chessboard.cols = cols;
  extract.chessboard.rows = rows;
  extract.square_size_m = square;
  NullProgress progress;
  RunTargetExtractor(extract, progress);
  CameraCalibratorOptions calibrate;
  calibrate.database_path = extract.database_path;
  calibrate.output_path = (dir / "cal").string();
  calibrate.calibration.estimate_board_warp = false;  // the flat board mrcal is to catch
  RunCameraCalibrator(calibrate, NoProgress());
  CrossCheckOptions options;
  options.database_path = extract.database_path;
  options.input_calibration = (dir / "cal/calibration.yaml").string();
  options.output_path = (dir / "check").string();
  options.folds = folds;
  const CrossCheckResult result = RunCrossCheck(options, NoProgress());
  std::cout << CrossCheckText(result);
  return result;
}

// The bar on a rendered set: the two agree to < 0.05 px mean.
TEST(CrossCheck, SharedRenderedSetAgrees) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  const CrossCheckResult result =
      CheckSharedSet(shared / "datasets/rendered/chess_air_distorted/images", "RADIAL", 10, 7, 0.02,
                     dir.path(), 3);
  EXPECT_LT(result.diff.mean_px, 0.05);
  EXPECT_TRUE(result.pass);
}

// The real in-air set: the flat-board calibration and mrcal's disagree by
// ~21 px in fx and ~28 px in cx (the issue: about 22 and 29 with OpenCV's
// corners); the cause is the board warp, and with it the two agree.
TEST(CrossCheck, RealInAirSetBlamesTheBoardWarp) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  const CrossCheckResult result =
      CheckSharedSet(shared / "datasets/real-dome/air", "OPENCV", 8, 6, 0.03, dir.path(), 2);
  EXPECT_FALSE(result.pass);
  ASSERT_GE(result.parameters.size(), 4u);
  EXPECT_GT(result.parameters[0].mrcal - result.parameters[0].portcal, 10.0);  // fx
  EXPECT_GT(result.parameters[2].mrcal - result.parameters[2].portcal, 10.0);  // cx
  ASSERT_FALSE(result.causes.empty());
  EXPECT_EQ(result.causes.front().rfind("board warp", 0), 0u) << result.causes.front();
  ASSERT_TRUE(result.rerun_diff.has_value());
  EXPECT_LT(result.rerun_diff->p95_px, result.max_diff_px);
  // The verdict: CHECK, for mrcal's disagreement, naming the re-run that
  // agrees; first in cross_check.txt.
  ASSERT_TRUE(result.verdict.has_value());
  EXPECT_EQ(result.verdict->status, VerdictStatus::kCheck) << result.verdict->Summary();
  EXPECT_EQ(result.verdict->lines.front().rule, "mrcal");
  EXPECT_NE(result.verdict->lines.front().text.find("agrees"), std::string::npos)
      << result.verdict->lines.front().text;
  EXPECT_EQ(testing::ReadFileToString(dir / "check/cross_check.txt").find("Verdict: CHECK"),
            testing::ReadFileToString(dir / "check/cross_check.txt").find("Verdict:"));
}

}  // namespace
}  // namespace portcal
