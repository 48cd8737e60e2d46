// Auto-calibration of a camera like a real one: strong radial distortion, an
// off-centre principal point, tangential terms and fx != fy, behind a tilted
// flat port, the intrinsics unknown (the mapper starts without distortion).
// Before the first radial term was estimated from the matches (and a
// focal length drifting beyond 1.25 x the markers' made the mapper start
// again), this render ended with f 653 px off, reported at 8 sigma
// (docs/auto_calibration.md). Also: the same images give the same
// calibration, and what the calibration cannot be trusted with is said.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "pipelines/auto_calibrator.h"
#include "pipelines/synthesize/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

constexpr double kDegree = M_PI / 180.0;

// A wide-angle lens (k1 = -0.3) with its principal point (10, -7.5) px off
// the centre, behind a flat port tilted 2.5 deg, 15 views of the two-face
// target at 0.3-0.8 m, 960 x 540.
const char* kWideLensBehindFlatPort = R"(name: wide
num_images: 15
camera: {model: OPENCV, width: 960, height: 540, params: [452.0, 450.5, 490.0, 262.5, -0.30, 0.09, 0.0012, 0.0009]}
housing: {model: FLATPORT, params: [0.0436194, 0.0, 0.9990482, 0.03, 0.008, 1.0, 1.473, 1.334]}
poses: {distance: [0.3, 0.8], tilt_max_deg: 45, roll_max_deg: 180, visibility: markers, border_margin_px: 10, max_view_angle_deg: 70}
render: {spp: 4, noise_sigma: 1.0, white: 220, black: 30, background: 110}
)";

AutoCalibrationResult Calibrate(const fs::path& images, const fs::path& out) {
  AutoCalibratorOptions options;
  options.image_path = images.string();
  options.output_path = out.string();
  options.camera_model = "OPENCV";
  options.housing.model = "FLATPORT";
  options.housing.params = "0,0,1,0.03,0.008,1,1.473,1.334";  // untilted, the distance roughly known
  options.marker_side_length_m = 0.06;
  NullProgress progress;
  return RunAutoCalibrator(options, progress);
}

TEST(AutoCalibrationRealCameras, WideOffCentreLensBehindATiltedFlatPortAndTheSameTwice) {
  testing::TempDir dir;
  std::ofstream(dir.path() / "set.yaml") << kWideLensBehindFlatPort << testing::kTwoFaceTargetYaml;
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir.path() / "set.yaml").string();
  synthesize.output_path = (dir.path() / "set").string();
  synthesize.seed = 1;
  NullProgress progress;
  Synthesize(synthesize, progress);
  const GroundTruth truth = ReadGroundTruth(dir.path() / "set" / "ground_truth.yaml");

  const AutoCalibrationResult result = Calibrate(dir.path() / "set" / "images", dir.path() / "out");
  EXPECT_EQ(result.num_registered, 15);
  const CalibrationReport& r = result.refined.report;
  ASSERT_TRUE(r.housing);
  // The issue's goals (|df| <= 1 px, principal point <= 1 px, normal <=
  // 0.05 deg, distance <= 2 mm), each within 3 sigma. Measured: |df| 0.08 /
  // 0.05 px, dc (-0.15, +0.04) px, normal 0.022 deg, distance +0.66 mm.
  for (int i : {0, 1, 2, 3}) {
    const double error = std::abs(r.camera.params[i] - truth.camera.params[i]);
    EXPECT_LT(error, 1.0) << "parameter " << i;
    EXPECT_LT(error, 3 * r.parameters_std_dev[i]) << "parameter " << i;
  }
  EXPECT_NEAR(r.camera.params[4], -0.30, 3 * r.parameters_std_dev[4]);
  const Eigen::Vector3d normal(r.housing->params[0], r.housing->params[1], r.housing->params[2]);
  const Eigen::Vector3d true_normal(truth.housing->params[0], truth.housing->params[1], truth.housing->params[2]);
  const double angle = std::acos(std::min(1.0, normal.normalized().dot(true_normal.normalized())));
  const double angle_sigma = std::hypot(r.housing_std_dev[0], r.housing_std_dev[1]);
  EXPECT_LT(angle, 0.05 * kDegree);
  EXPECT_LT(angle, 3 * angle_sigma);
  const double distance_error = std::abs(r.housing->params[3] - truth.housing->params[3]);
  EXPECT_LT(distance_error, 0.002);
  EXPECT_LT(distance_error, 3 * r.housing_std_dev[3]);
  EXPECT_TRUE(r.warnings.empty());

  // Again, same images and options: the same calibration (RANSAC seeded by
  // --random_seed; before, two runs of one set gave f 166 and 178 px off).
  // Not to the bit: Ceres sums the residual blocks of its two threads in
  // whichever order they finish, which moves the 9th digit (measured: f
  // 452.083054531 / 452.083054906 px), a millionth of a standard deviation.
  const AutoCalibrationResult again = Calibrate(dir.path() / "set" / "images", dir.path() / "again");
  for (size_t i = 0; i < r.camera.params.size(); ++i) {
    EXPECT_NEAR(again.refined.report.camera.params[i], r.camera.params[i], 1e-3 * r.parameters_std_dev[i]);
  }
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(again.refined.report.housing->params[i], r.housing->params[i], 1e-3 * r.housing_std_dev[i] + 1e-12);
  }
}

CalibrationReport FlatPortReport(double focal, double focal_std_dev, double port_distance) {
  CalibrationReport r;
  r.camera = Camera::FromModelName("RADIAL", focal, 1920, 1080);
  r.parameters_std_dev = {focal_std_dev, 0.5, 0.5, 0.001, 0.001};
  r.housing = Housing::FromName("FLATPORT", {0, 0, 1, port_distance, 0.008, 1, 1.473, 1.334}, "test");
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
    EXPECT_NE(std::string(e.what()).find("--ImageReader.camera_params"), std::string::npos) << e.what();
  }
}

TEST(AutoCalibrationRealCameras, WhatTheViewsLeaveUndeterminedIsAWarningFirstInTheReport) {
  CalibrationReport r = FlatPortReport(1310, 20, 0.39);  // sigma 1.5 % of f
  JudgeAutoCalibration(1300.0, &r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("focal length is poorly determined"), std::string::npos) << r.warnings[0];
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

  // A well-determined calibration: no warning.
  CalibrationReport good = FlatPortReport(1310, 0.7, 0.03);
  JudgeAutoCalibration(1290.0, &good);
  EXPECT_TRUE(good.warnings.empty());
}

}  // namespace
}  // namespace portcal
