// Auto-calibration of cameras like real ones (issue 21): strong radial
// distortion or a fisheye, an off-centre principal point, tangential terms
// and fx != fy, behind a tilted flat port, a decentred dome or in air, 2-
// and 3-face targets, the intrinsics unknown (the mapper starts without
// distortion). Before the first radial term was estimated from the
// matches (and a focal length drifting beyond 1.25 x the markers' made the
// mapper start again), the wide lens behind the flat port ended with f
// 653 px off, reported at 8 sigma (docs/dev/auto_calibration_notes.md). Also: the
// same images give the same calibration, and what the calibration cannot
// be trusted with is said.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "pipelines/stages/auto_calibrator.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr double kDegree = M_PI / 180.0;

// 15 views of 960 x 540 at 0.3-0.8 m (the issue's goals are for 30 views
// of 1920 x 1080; at half the size and half the views the focal length's
// and principal point's errors in pixels stay alike, those of the housing
// in metres grow about 2.8 times).
const char* kViews = R"(num_images: 15
poses: {distance: [0.3, 0.8], tilt_max_deg: 45, roll_max_deg: 180, visibility: markers, border_margin_px: 10, max_view_angle_deg: 70}
render: {spp: 4, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)";
// A wide-angle lens (k1 = -0.3) with its principal point (10, -7.5) px off
// the centre.
const char* kWideLens =
    "camera: {model: OPENCV, width: 960, height: 540, params: [452.0, 450.5, 490.0, 262.5, -0.30, "
    "0.09, 0.0012, "
    "0.0009]}\n";
// A fisheye (about 100 deg across) with its principal point (-8, 6) px off.
const char* kFisheye =
    "camera: {model: OPENCV_FISHEYE, width: 960, height: 540, params: [380.0, 379.0, 472.0, 276.0, "
    "0.06, -0.02, "
    "0.004, -0.001]}\n";
const char* kFlatPortTilted =
    "housing: {model: FLATPORT, params: [0.0436194, 0.0, 0.9990482, 0.03, 0.008, 1.0, 1.473, "
    "1.334]}\n";
const char* kFlatPortGuess =
    "0,0,1,0.03,0.008,1,1.473,1.334";  // untilted, the distance roughly known
const char* kDomeDecentred =
    "housing: {model: DOMEPORT, params: [0.003, -0.002, 0.004, 0.05, 0.006, 1.0, 1.473, 1.334]}\n";
const char* kDomeGuess = "0,0,0,0.05,0.006,1,1.473,1.334";

struct FamilyMember {
  std::string camera_yaml, housing_yaml, target_yaml;
  std::string camera_model, housing_model, housing_guess;
  int seed = 1;
};

struct MemberRun {
  GroundTruth truth;
  AutoCalibratorSummary result;
};

fs::path Render(const fs::path& dir, const FamilyMember& m) {
  const std::string housing = m.housing_yaml.empty() ? "housing: null\n" : m.housing_yaml;
  std::ofstream(dir / "set.yaml") << "name: member\n"
                                  << kViews << m.camera_yaml << housing << m.target_yaml;
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  synthesize.seed = m.seed;
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  return dir / "set";
}

AutoCalibratorSummary Calibrate(const FamilyMember& m, const fs::path& images, const fs::path& out,
                                int num_threads) {
  AutoCalibratorOptions options;
  options.image_path = images.string();
  options.output_path = out.string();
  options.camera_model = m.camera_model;
  options.housing = HousingFromText(m.housing_model, m.housing_guess);
  options.marker_scale.side_length_m = 0.06;
  options.num_threads = num_threads;
  NullProgress progress;
  return RunAutoCalibrator(options, progress);
}

MemberRun RenderAndCalibrate(const fs::path& dir, const FamilyMember& m, int num_threads = 2) {
  const fs::path set = Render(dir, m);
  MemberRun run;
  run.truth = ReadGroundTruth(set / "ground_truth.yaml");
  run.result = Calibrate(m, set / "images", dir / "out", num_threads);
  EXPECT_EQ(run.result.num_registered, 15);
  return run;
}

// Prints the errors in sigmas, for docs/dev/auto_calibration_notes.md.
void PrintErrors(const CalibrationReport& r, const GroundTruth& truth) {
  std::cout << "errors (sigmas):";
  for (size_t i = 0; i < 5; ++i) {
    const double e = r.camera.params[i] - truth.camera.params[i];
    std::cout << " " << e << " (" << e / r.parameters_std_dev[i] << ")";
  }
  if (r.housing) {
    std::cout << " | housing";
    for (size_t i = 0; i < 4; ++i) {
      const double e = r.housing->params[i] - truth.housing->params[i];
      std::cout << " " << e;
      if (r.housing_std_dev[i] > 0) std::cout << " (" << e / r.housing_std_dev[i] << ")";
    }
  }
  std::cout << "\n";
}

// The issue's goals for the intrinsics: fx, fy, cx, cy each within 1 px and
// 3 sigma of the truth, and the first distortion term within 3 sigma.
void ExpectIntrinsicsGoals(const CalibrationReport& r, const GroundTruth& truth) {
  PrintErrors(r, truth);
  for (int i : {0, 1, 2, 3}) {
    const double error = std::abs(r.camera.params[i] - truth.camera.params[i]);
    EXPECT_LT(error, 1.0) << "parameter " << i;
    EXPECT_LT(error, 3 * r.parameters_std_dev[i]) << "parameter " << i;
  }
  EXPECT_NEAR(r.camera.params[4], truth.camera.params[4], 3 * r.parameters_std_dev[4]);
}

// The flat port's: normal within 0.05 deg, distance within 2 mm, each
// within 3 sigma.
void ExpectFlatPortGoals(const CalibrationReport& r, const GroundTruth& truth) {
  ASSERT_TRUE(r.housing);
  const Eigen::Vector3d normal(r.housing->params[0], r.housing->params[1], r.housing->params[2]);
  const Eigen::Vector3d true_normal(truth.housing->params[0], truth.housing->params[1],
                                    truth.housing->params[2]);
  const double angle = std::acos(std::min(1.0, normal.normalized().dot(true_normal.normalized())));
  const double angle_sigma = std::hypot(r.housing_std_dev[0], r.housing_std_dev[1]);
  EXPECT_LT(angle, 0.05 * kDegree);
  EXPECT_LT(angle, 3 * angle_sigma);
  const double distance_error = std::abs(r.housing->params[3] - truth.housing->params[3]);
  EXPECT_LT(distance_error, 0.002);
  EXPECT_LT(distance_error, 3 * r.housing_std_dev[3]);
}

TEST(AutoCalibrationRealCameras, WideOffCentreLensBehindATiltedFlatPortAndTheSameTwice) {
  testing::TempDir dir;
  const FamilyMember wide{kWideLens, kFlatPortTilted, testing::kTwoFaceTargetYaml,
                          "OPENCV",  "FLATPORT",      kFlatPortGuess,
                          1};
  // One thread: bitwise repeatable (see the second run below).
  const MemberRun run = RenderAndCalibrate(dir.path(), wide, 1);
  const CalibrationReport& r = run.result.refined.report;
  // Measured: df -0.12 / -0.16 px, dc (-0.08, +0.06) px, normal 0.019 deg,
  // distance +1.07 mm (1.1 sigma).
  ExpectIntrinsicsGoals(r, run.truth);
  ExpectFlatPortGoals(r, run.truth);
  EXPECT_TRUE(r.warnings.empty());

  // Again, same images and options: the same calibration (RANSAC seeded by
  // --random_seed; before, two runs of one set gave f 166 and 178 px off).
  // With one thread to the bit. With two, Ceres sums the residual blocks
  // (and the Schur complement's cells) of its threads in whichever order
  // they finish, which moves the 9th digit; under CI's load that once
  // flipped which observations passed a threshold, and two runs differed
  // by 0.04 sigma in the port distance (docs/dev/auto_calibration_notes.md).
  const AutoCalibratorSummary again =
      Calibrate(wide, dir.path() / "set" / "images", dir.path() / "again", 1);
  for (size_t i = 0; i < r.camera.params.size(); ++i) {
    EXPECT_EQ(again.refined.report.camera.params[i], r.camera.params[i]) << "parameter " << i;
  }
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(again.refined.report.housing->params[i], r.housing->params[i])
        << "housing parameter " << i;
  }
}

TEST(AutoCalibrationRealCameras, WideOffCentreLensInAirWithAThreeFaceTarget) {
  testing::TempDir dir;
  const MemberRun run = RenderAndCalibrate(
      dir.path(), {kWideLens, "", testing::kThreeFaceTargetYaml, "OPENCV", "", "", 2});
  const CalibrationReport& r = run.result.refined.report;
  EXPECT_FALSE(r.housing);
  // Measured: df -0.18 / -0.14 px, dc (-0.10, +0.18) px.
  ExpectIntrinsicsGoals(r, run.truth);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(AutoCalibrationRealCameras, OffCentreFisheyeBehindATiltedFlatPort) {
  // With the first radial term searched from the matches (as for the
  // pinhole models) this render's k1 started at 0.35 for 0.06 and the port
  // ended 207 mm away (warned); a fisheye model starts at k = 0.
  testing::TempDir dir;
  const MemberRun run =
      RenderAndCalibrate(dir.path(), {kFisheye, kFlatPortTilted, testing::kTwoFaceTargetYaml,
                                      "OPENCV_FISHEYE", "FLATPORT", kFlatPortGuess, 1});
  const CalibrationReport& r = run.result.refined.report;
  // Measured: df -0.16 / -0.19 px, dc (-0.43, +0.32) px (1.6 sigma in cx),
  // normal 0.036 deg, distance +1.37 mm.
  ExpectIntrinsicsGoals(r, run.truth);
  ExpectFlatPortGoals(r, run.truth);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(AutoCalibrationRealCameras, OffCentreFisheyeBehindADecentredDomeSaysWhatItCannotTellApart) {
  // A dome decentred along its axis magnifies like a longer focal length;
  // with the intrinsics unknown these views hardly tell f from Cz (the
  // goal of 0.2 mm for the dome's centre is out of reach: Cz's sd is
  // 2 mm). The report must say so first, and the errors stay within 3
  // sigma.
  testing::TempDir dir;
  const MemberRun run =
      RenderAndCalibrate(dir.path(), {kFisheye, kDomeDecentred, testing::kThreeFaceTargetYaml,
                                      "OPENCV_FISHEYE", "DOMEPORT", kDomeGuess, 1});
  const CalibrationReport& r = run.result.refined.report;
  ASSERT_TRUE(r.housing);
  PrintErrors(r, run.truth);
  for (int i : {0, 1, 2, 3}) {
    EXPECT_LT(std::abs(r.camera.params[i] - run.truth.camera.params[i]),
              3 * r.parameters_std_dev[i])
        << i;
  }
  for (int k : {0, 1, 2}) {
    EXPECT_LT(std::abs(r.housing->params[k] - run.truth.housing->params[k]),
              3 * r.housing_std_dev[k])
        << "C" << k;
  }
  bool said = false;
  for (const std::string& w : r.warnings)
    said |= w.find("and Cz are correlated") != std::string::npos;
  EXPECT_TRUE(said) << "no warning of the f-Cz trade";
  // Its focal length's sd (1 % of it) comes from the same trade: one start,
  // not three (their models were identical).
  EXPECT_EQ(run.result.refined.num_geometry_warnings, static_cast<int>(r.warnings.size()));
}

CalibrationReport FlatPortReport(double focal, double focal_std_dev, double port_distance) {
  CalibrationReport r;
  r.camera = Camera::FromModelName("RADIAL", focal, 1920, 1080);
  r.parameters_std_dev = {focal_std_dev, 0.5, 0.5, 0.001, 0.001};
  r.housing =
      Housing::FromName("FLATPORT", {0, 0, 1, port_distance, 0.008, 1, 1.473, 1.334}, "test");
  r.housing_std_dev = {0.001, 0.001, 0, 0.001, 0, 0, 0, 0};
  CalibratedView view;
  view.image_name = "a.png";
  view.cam_from_target.translation = Eigen::Vector3d(0.1, 0, 0.6);
  r.views.push_back(view);
  return r;
}

TEST(AutoCalibrationRealCameras, AFocalLengthTheMarkersRuleOutIsAnError) {
  // The issue's failure: f 166 px off; the markers had said 1260 px.
  CalibrationReport r = FlatPortReport(1640, 110, 0.39);
  try {
    JudgeAutoCalibration(1260.0, &r);
    FAIL() << "no error";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("markers' estimate 1260"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--ImageReader.camera_params"), std::string::npos)
        << e.what();
  }
}

TEST(AutoCalibrationRealCameras, WhatTheViewsLeaveUndeterminedIsAWarningFirstInTheReport) {
  CalibrationReport r = FlatPortReport(1310, 20, 0.39);  // sigma 1.5 % of f
  JudgeAutoCalibration(1300.0, &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("focal length is poorly determined"), std::string::npos)
      << r.warnings[0];
  testing::TempDir dir;
  WriteCalibrationReport(r, dir.path());
  std::ifstream text(dir.path() / "calibration.txt");
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(text, line)) lines.push_back(line);
  ASSERT_GE(lines.size(), 4u);
  EXPECT_EQ(lines[3].rfind("WARNING: the focal length is poorly determined", 0), 0u) << lines[3];
  const CalibrationReport back = ReadCalibrationReport(dir.path() / "calibration.yaml");
  EXPECT_EQ(back.warnings, r.warnings);

  // No finite standard deviation (negative in a report): undetermined,
  // which is a warning, not "held fixed".
  CalibrationReport undetermined = FlatPortReport(1310, -1, 0.03);
  JudgeAutoCalibration(1300.0, &undetermined);
  ASSERT_EQ(undetermined.warnings.size(), 1u);
  EXPECT_NE(undetermined.warnings[0].find("focal length is undetermined"), std::string::npos);

  // A well-determined calibration: no warning.
  CalibrationReport good = FlatPortReport(1310, 0.7, 0.03);
  JudgeAutoCalibration(1290.0, &good);
  EXPECT_TRUE(good.warnings.empty());
}

}  // namespace
}  // namespace portcal
