// calibration_evaluator: the true calibration of a rendered set evaluates
// at the corners' noise with no pattern, a slightly wrong one (k1 off by
// 0.02) shows both a larger RMS and a residual pattern well above what
// noise gives; K-fold cross-validation holds each view out once; bad input
// names what is wrong.
#include "pipelines/stages/calibration_evaluator.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "pipelines/calibration/calibration_report.h"
#include "tests/pipelines/stages/live_test_setup.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

const char* const kSetYaml = R"(name: evaluator
seed: 31
num_images: 12
camera: {model: OPENCV, width: 640, height: 480, params: [505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007]}
housing: null
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 20, border_margin_px: 15}
render: {spp: 2, blur_sigma: 0.6, noise_sigma: 2.0}
)";

struct Fixture {
  testing::TempDir dir;
  GroundTruth truth;
  CalibrationEvaluatorOptions options;

  Fixture() {
    truth = testing::RenderSet(dir, kSetYaml);
    testing::ExtractBoard(dir / "set/images", dir / "set.db", false);
    options.database_path = (dir / "set.db").string();
    options.output_path = (dir / "evaluation").string();
  }

  // The truth, with k1 moved by `dk1`, as a calibration.yaml whose own
  // RMS (of the views it was fitted to) is `own_rms_px` (0: none).
  std::string Calibration(const std::string& name, double dk1, double own_rms_px = 0) const {
    CalibrationReport report;
    report.camera = truth.camera;
    report.camera.params[4] += dk1;
    report.overall_rms_px = own_rms_px;
    WriteCalibrationReport(report, dir / name);
    return (dir / name / "calibration.yaml").string();
  }
};

TEST(CalibrationEvaluator, AWrongLensShowsInTheRmsAndInThePattern) {
  Fixture f;
  // Each as if fitted to views like these: its own RMS the corners' noise
  // (the truth's held-out RMS below, 0.030 px).
  f.options.input_calibration = f.Calibration("truth", 0, 0.03);
  const HeldOutEvaluation right = RunCalibrationEvaluator(f.options, NoProgress()).evaluation;
  const std::string right_status =
      YAML::LoadFile(f.options.output_path + "/evaluation.yaml")["verdict"]["status"]
          .as<std::string>();
  f.options.input_calibration = f.Calibration("wrong", 0.02, 0.03);
  const HeldOutEvaluation wrong = RunCalibrationEvaluator(f.options, NoProgress()).evaluation;
  const YAML::Node wrong_verdict =
      YAML::LoadFile(f.options.output_path + "/evaluation.yaml")["verdict"];
  std::printf(
      "held out: true lens %.4f px (pattern %.4f, noise alone %.4f); k1 + 0.02: %.4f px (pattern "
      "%.4f)\n",
      right.rms_px, right.systematic_px, right.noise_floor_px, wrong.rms_px, wrong.systematic_px);
  EXPECT_EQ(right.views.size(), 12u);
  EXPECT_EQ(right.num_points, 12 * 54);
  // The rendered corners' noise is a few hundredths of a pixel.
  EXPECT_LT(right.rms_px, 0.08);
  // Noise alone: the cells' mean residuals are what averaging predicts
  // (within a factor, for the few points per cell and the rendering's
  // own small biases).
  EXPECT_LT(right.systematic_px, 2.5 * right.noise_floor_px);
  EXPECT_GT(wrong.rms_px, 2 * right.rms_px);
  // The wrong lens's pattern stands far above the noise's. (Against its
  // own cells' scatter it stands less: each view's pose absorbs part of
  // the error differently, which widens the scatter too.)
  EXPECT_GT(wrong.systematic_px, 4 * right.noise_floor_px);
  EXPECT_GT(wrong.systematic_px, 4 * right.systematic_px);
  EXPECT_TRUE(fs::exists(fs::path(f.options.output_path) / "evaluation.yaml"));
  EXPECT_TRUE(fs::exists(fs::path(f.options.output_path) / "evaluation.txt"));
  // The verdict: the truth OK; the wrong lens CHECK, these views fitted
  // far worse than the calibration's own (its pattern against its own
  // cells' scatter stays below the rule's 3x, as said above).
  EXPECT_EQ(right_status, "OK");
  EXPECT_EQ(wrong_verdict["status"].as<std::string>(), "CHECK");
  ASSERT_GE(wrong_verdict["reasons"].size(), 1u);
  EXPECT_EQ(wrong_verdict["reasons"][0].as<std::string>().rfind("held out: ", 0), 0u)
      << YAML::Dump(wrong_verdict);
  EXPECT_EQ(testing::ReadFileToString(fs::path(f.options.output_path) / "evaluation.txt")
                .rfind("Verdict: CHECK", 0),
            0u);
}

TEST(CalibrationEvaluator, CrossValidationHoldsEachViewOutOnce) {
  Fixture f;
  f.options.input_calibration = f.Calibration("truth", 0);
  f.options.folds = 3;
  const CalibrationEvaluatorSummary summary = RunCalibrationEvaluator(f.options, NoProgress());
  ASSERT_EQ(summary.folds.size(), 3u);
  int held_out = 0;
  for (const FoldEvaluation& fold : summary.folds) {
    EXPECT_EQ(fold.num_train + fold.num_test, 12);
    held_out += fold.num_test;
    EXPECT_GT(fold.train_rms_px, 0);
    EXPECT_LT(fold.test_rms_px, 0.1) << "fold " << fold.fold;
  }
  EXPECT_EQ(held_out, 12);
  // Fitted to 8 views, the lens predicts the other 4 about as well as the
  // truth does: held out, the RMS is the noise plus the fit's own error.
  EXPECT_GT(summary.cross_validation_rms_px, 0.9 * summary.evaluation.rms_px);
  EXPECT_LT(summary.cross_validation_rms_px, 2 * summary.evaluation.rms_px);
}

TEST(CalibrationEvaluator, BadInputNamesWhatIsWrong) {
  Fixture f;
  CalibrationReport other;
  other.camera = Camera::FromModelName("OPENCV", 500, 1280, 720);
  WriteCalibrationReport(other, f.dir / "other");
  f.options.input_calibration = (f.dir / "other/calibration.yaml").string();
  try {
    RunCalibrationEvaluator(f.options, NoProgress());
    ADD_FAILURE() << "a calibration of another size accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("1280x720"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(f.options.output_path));
  f.options.input_calibration = f.Calibration("truth", 0);
  f.options.folds = 1;
  EXPECT_THROW(RunCalibrationEvaluator(f.options, NoProgress()), OptionError);
  f.options.folds = 13;
  EXPECT_THROW(RunCalibrationEvaluator(f.options, NoProgress()), OptionError);
}

}  // namespace
}  // namespace portcal
