// --input_calibration in the formats users already have: portcal's own
// exports (OpenCV FileStorage YAML, ROS camera_info YAML, mrcal's
// .cameramodel) read back project exactly like the camera written; the real
// set's ROS file reads as its numbers say; a file of none of the formats is
// an error that names the formats and the missing key.
#include "pipelines/calibration/calibration_report.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/opencv_camera_file.h"
#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

Camera MakeCamera(const std::string& model, const std::vector<double>& params) {
  Camera camera;
  camera.model_id = CameraModelNameToId(model);
  camera.width = 1440;
  camera.height = 1080;
  camera.params = params;
  return camera;
}

// The largest distance between the two cameras' pixels of points spread
// over the field of view.
double MaxProjectionDifferencePx(const Camera& a, const Camera& b) {
  double max_diff = 0;
  for (double x = -0.35; x <= 0.35; x += 0.05) {
    for (double y = -0.25; y <= 0.25; y += 0.05) {
      const Eigen::Vector3d point(x, y, 1.0);
      const auto pa = a.ImgFromCam(point);
      const auto pb = b.ImgFromCam(point);
      EXPECT_TRUE(pa && pb);
      if (pa && pb) max_diff = std::max(max_diff, (*pa - *pb).norm());
    }
  }
  return max_diff;
}

TEST(ReadCalibrationReport, ReadsOpenCvRosAndMrcalFilesAsTheCameraWritten) {
  testing::TempDir dir;
  const std::vector<Camera> cameras = {
      MakeCamera("OPENCV", {2412.1, 2418.7, 752.3, 571.9, -0.37, 0.21, 0.0015, 0.0004}),
      MakeCamera("FULL_OPENCV", {2412.1, 2418.7, 752.3, 571.9, -0.37, 0.21, 0.0015, 0.0004, -0.05,
                                 0.01, 0.02, -0.03}),
      MakeCamera("RADIAL", {2412.1, 752.3, 571.9, -0.37, 0.21}),
      MakeCamera("PINHOLE", {2412.1, 2418.7, 752.3, 571.9}),
      MakeCamera("OPENCV_FISHEYE", {700.2, 701.1, 719.4, 541.2, 0.06, -0.02, 0.004, -0.001}),
  };
  for (const Camera& camera : cameras) {
    const std::string model = camera.ModelName();
    std::vector<fs::path> files = {dir / (model + "_opencv.yaml"), dir / (model + "_ros.yaml")};
    WriteOpenCvCameraYaml(camera, files[0]);
    WriteRosCameraInfoYaml(camera, "test", files[1]);
    if (model != "OPENCV_FISHEYE") {  // mrcal has no COLMAP-exact fisheye
      files.push_back(dir / (model + ".cameramodel"));
      WriteMrcalCameraModel(camera, Rigid3d(), files.back());
    }
    for (const fs::path& file : files) {
      const CalibrationReport read = ReadCalibrationReport(file);
      EXPECT_EQ(read.camera.width, camera.width) << file;
      EXPECT_EQ(read.camera.height, camera.height) << file;
      EXPECT_LT(MaxProjectionDifferencePx(read.camera, camera), 1e-9)
          << file << " read as " << read.camera.ModelName();
      EXPECT_FALSE(read.housing) << file;
    }
  }
}

TEST(ReadCalibrationReport, ReadsTheRealSetsRosCameraInfo) {
  PORTCAL_REQUIRE_SHARED(shared);
  const CalibrationReport read = ReadCalibrationReport(shared / "datasets/real-dome/air_ost.yaml");
  // plumb_bob with k3 = 0: OPENCV, the principal point half a pixel on
  // (COLMAP's convention).
  ASSERT_EQ(read.camera.ModelName(), "OPENCV");
  const std::vector<double> expected = {2424.65845, 2430.55993, 765.71063, 570.19265,
                                        -0.370666,  0.205071,   0.001513,  0.000373};
  ASSERT_EQ(read.camera.params.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i)
    EXPECT_DOUBLE_EQ(read.camera.params[i], expected[i]) << i;
  EXPECT_EQ(read.camera.width, 1440u);
  EXPECT_EQ(read.camera.height, 1080u);
}

// A report as calibmar writes it: the shared set's calibration_condria.yaml
// (from EmilioOlivastri/calibmar, config/calibration_condria.yaml, a BSD
// calibmar fork), as is. calibmar keeps the standard deviations, RMS and
// target in comments.
const char* const kCalibmarReport = R"(model: OPENCV_FISHEYE
# fx, fy, cx, cy, k1, k2, k3, k4
parameters: [2641.404135, 2644.628977, 1990.530781, 1055.024804, 0.05608049163, 0.07435086083, -0.001746305011, 0.01681019584]
non_svp_model: FLATPORT
# Nx, Ny, Nz, int_dist, int_thick, na, ng, nw (Note that [Nx, Ny, Nz] must be unit vector)
non_svp_parameters: [-0.004348434312, -0.00752015894, 0.9999622685, 0.03480104832, 0.008, 1, 1.48899, 1.334]
# non_svp_est_std_dev: 0.0002753845735, 0.0002450684841, 2.170503842e-06, 0.0004740286295, 0, 0, 0, 0
width: 3840
height: 2160
# overall_rms: 2.61747377
# target: aruco grid board, APRILTAG_36h11, 6, 6, 0.088000, 0.300000, 2, bl, hor
)";

void ExpectTheCalibmarReport(const CalibrationReport& read) {
  EXPECT_EQ(read.camera.ModelName(), "OPENCV_FISHEYE");
  EXPECT_EQ(read.camera.width, 3840u);
  EXPECT_EQ(read.camera.height, 2160u);
  ASSERT_EQ(read.camera.params.size(), 8u);
  EXPECT_DOUBLE_EQ(read.camera.params[0], 2641.404135);
  EXPECT_DOUBLE_EQ(read.camera.params[3], 1055.024804);  // calibmar's pixels are COLMAP's: no shift
  EXPECT_DOUBLE_EQ(read.camera.params[7], 0.01681019584);
  ASSERT_TRUE(read.housing.has_value());
  EXPECT_EQ(read.housing->ModelName(), "FLATPORT");
  EXPECT_DOUBLE_EQ(read.housing->params[3], 0.03480104832);
  EXPECT_DOUBLE_EQ(read.housing->params[6], 1.48899);
  ASSERT_EQ(read.housing_std_dev.size(), 8u);
  EXPECT_DOUBLE_EQ(read.housing_std_dev[0], 0.0002753845735);
  EXPECT_DOUBLE_EQ(read.housing_std_dev[3], 0.0004740286295);
  EXPECT_DOUBLE_EQ(read.overall_rms_px, 2.61747377);
  EXPECT_EQ(read.target_description,
            "aruco grid board, APRILTAG_36h11, 6, 6, 0.088000, 0.300000, 2, bl, hor");
}

TEST(ReadCalibrationReport, ReadsCalibmarsOwnReportWithItsCommentedDeviations) {
  const testing::TempDir dir;
  std::ofstream(dir / "calibration.yaml") << kCalibmarReport;
  ExpectTheCalibmarReport(ReadCalibrationReport(dir / "calibration.yaml"));
  // A comment that should hold numbers and does not: an error naming the file.
  std::string broken = kCalibmarReport;
  broken.replace(broken.find("2.61747377"), 10, "n/a");
  std::ofstream(dir / "broken.yaml") << broken;
  try {
    ReadCalibrationReport(dir / "broken.yaml");
    ADD_FAILURE() << "a comment without numbers accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.yaml"), std::string::npos) << e.what();
  }
}

TEST(ReadCalibrationReport, ReadsTheSharedCalibmarReport) {
  PORTCAL_REQUIRE_SHARED(shared);
  ExpectTheCalibmarReport(
      ReadCalibrationReport(shared / "datasets/calibmar-reports/calibration_condria.yaml"));
}

// The covariances a later stage propagates are written in full and read
// back; one that is not a covariance is refused, naming the key.
TEST(ReadCalibrationReport, CovariancesRoundTripAndAMalformedOneIsNamed) {
  testing::TempDir dir;
  CalibrationReport report;
  report.camera = MakeCamera("RADIAL", {700, 401.3, 298.7, -0.1, 0.02});
  report.parameters_std_dev = {1, 0.5, 0.5, 0.01, 0.02};
  report.parameters_covariance = Eigen::MatrixXd::Identity(5, 5);
  report.parameters_covariance(0, 3) = report.parameters_covariance(3, 0) =
      1.0 / 3.0;  // not a short decimal
  report.housing =
      Housing::FromName("DOMEPORT", {0.001, -0.002, 0.003, 0.05, 0.006, 1.0, 1.49, 1.334}, "test");
  report.housing_std_dev = {1e-4, 1e-4, 2e-4, 0, 0, 0, 0, 0};
  report.housing_covariance = Eigen::MatrixXd::Zero(8, 8);
  report.housing_covariance.topLeftCorner<3, 3>() << 1e-8, 2e-9, 0, 2e-9, 1e-8, 0, 0, 0, 4e-8;
  WriteCalibrationReport(report, dir.path());
  const CalibrationReport read = ReadCalibrationReport(dir / "calibration.yaml");
  EXPECT_EQ(read.parameters_covariance, report.parameters_covariance);
  EXPECT_EQ(read.housing_covariance, report.housing_covariance);

  std::string text = testing::ReadFileToString(dir / "calibration.yaml");
  const size_t row = text.find("- [", text.find("parameters_covariance:"));
  text.replace(row, 3, "- [-5, ");  // a sixth value in the first row
  std::ofstream(dir / "broken.yaml") << text;
  try {
    ReadCalibrationReport(dir / "broken.yaml");
    ADD_FAILURE() << "a 5 x 5 covariance with a row of 6 accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("broken.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("parameters_covariance"), std::string::npos) << what;
  }
}

TEST(ReadCalibrationReport, AFileOfNoKnownFormatNamesTheFormatsAndTheKey) {
  testing::TempDir dir;
  const fs::path file = dir / "calib.yaml";
  std::ofstream(file) << "fx: 2400\nfy: 2400\n";
  try {
    ReadCalibrationReport(file);
    FAIL() << "read a file of no known format";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const char* named :
         {"calib.yaml", "'model'", "camera_matrix", ".cameramodel", "calibmar"}) {
      EXPECT_NE(what.find(named), std::string::npos) << named << " not in: " << what;
    }
  }
  std::ofstream(dir / "ros.yaml")
      << "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n";
  try {
    ReadCalibrationReport(dir / "ros.yaml");
    FAIL() << "read a camera_matrix without data";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera_matrix"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadCalibrationReport(dir / "missing.yaml"), InputError);
}

// A housing calibration whose views leave parameters undetermined (the
// real dome with the intrinsics refined: cx 334 px off, Cz at -23 mm, a
// lower RMS): a warning first in the report that names them and the fix.
TEST(ReportOf, UndeterminedParametersAreAWarningThatNamesThem) {
  HousingCalibrationResult result;
  result.camera =
      MakeCamera("OPENCV", {2412.1, 2418.7, 1054.3, 571.9, -0.37, 0.21, 0.0015, 0.0004});
  result.camera_std_dev = {2.1, 2.2, -1, 1.7, 0.001, 0.004, 0.0001, 0.0001};
  result.housing = Housing::FromName(
      "DOMEPORT", {0.001, -0.002, -0.023, 0.043552, 0.00375, 1, 1.495, 1.333}, "t");
  result.housing_std_dev = {0.0001, 0.0001, -1, 0, 0, 0, 0, 0};
  const CalibrationReport report = ReportOf(result, "chessboard");
  ASSERT_EQ(report.warnings.size(), 1u);
  const std::string& warning = report.warnings.front();
  for (const char* named : {"cx, Cz", "--Calibration.refine_intrinsics 0"}) {
    EXPECT_NE(warning.find(named), std::string::npos) << named << ": " << warning;
  }
  testing::TempDir dir;
  WriteCalibrationReport(report, dir.path());
  const std::string text = testing::ReadFileToString(dir / "calibration.txt");
  EXPECT_NE(text.find("WARNING: the views do not determine cx, Cz"), std::string::npos) << text;
  // A determined calibration: no warning, and the housing said in words.
  result.camera_std_dev[2] = 1.9;
  result.housing_std_dev[2] = 0.0002;
  const CalibrationReport good = ReportOf(result, "chessboard");
  EXPECT_TRUE(good.warnings.empty());
  WriteCalibrationReport(good, dir / "good");
  EXPECT_NE(testing::ReadFileToString(dir / "good/calibration.txt")
                .find("23.00 mm behind the camera's projection"),
            std::string::npos);
}

// The note a fitted board warp gets: the real in-air set's figures (sag
// 0.28 mm; held flat, fx 21.4 px lower).
TEST(BoardWarpNote, SaysTheSagItsSignificanceAndWhatFlatWouldChange) {
  CameraCalibrationResult warped;
  warped.camera = MakeCamera("OPENCV", {2433.4, 2437.1, 760.5, 557.5, -0.36, 0.18, 0.0013, 0.0015});
  warped.params_std_dev = {2.6, 2.7, 3.6, 2.9, 0.004, 0.04, 0.0002, 0.0002};
  warped.board_warp = Eigen::Vector2d(-0.084e-3, -0.278e-3);
  warped.board_warp_std_dev = Eigen::Vector2d(0.012e-3, 0.010e-3);
  warped.overall_rms_px = 0.188;
  CameraCalibrationResult flat = warped;
  flat.camera.params[0] = 2412.0;  // fx: -21.4 px, 8.2 sigma
  flat.camera.params[2] = 731.9;   // cx: -28.6 px, 7.9 sigma
  flat.overall_rms_px = 0.229;
  const std::string note = BoardWarpNote(warped, flat);
  for (const char* said :
       {"sag x -0.084 +- 0.012 mm, y -0.278 +- 0.010 mm", "significant (27.8 sigma)",
        "held flat, fx would be 2412.0 px (-21.4 px, 8.2 sigma)",
        "RMS 0.229 px instead of 0.188"}) {
    EXPECT_NE(note.find(said), std::string::npos) << said << ": " << note;
  }
  warped.board_warp = Eigen::Vector2d(0.01e-3, -0.02e-3);
  flat = warped;
  flat.camera.params[3] += 0.5;
  const std::string small = BoardWarpNote(warped, flat);
  EXPECT_NE(small.find("not significant (2.0 sigma)"), std::string::npos) << small;
  EXPECT_NE(small.find("cy would be"), std::string::npos) << small;
}

}  // namespace
}  // namespace portcal

namespace portcal {
namespace {

// Image names with quotes, backslashes, newlines, tabs and other scripts
// are written so that calibration.yaml reads back with the same names.
TEST(ReadCalibrationReport, ImageNamesOfAnyKindReadBack) {
  CalibrationReport report;
  report.camera = Camera::FromModelName("OPENCV", 500, 640, 480);
  const std::vector<std::string> names = {
      "it's.png",      "say \"cheese\".png", "back\\slash.png", "two\nlines.png",
      "tab\there.png", "sous l'eau/é.png",   "水中.png",        "- dash: colon.png"};
  for (const std::string& name : names) {
    CalibratedView view;
    view.image_name = name;
    report.views.push_back(view);
  }
  testing::TempDir dir;
  WriteCalibrationReport(report, dir.path());
  const CalibrationReport back = ReadCalibrationReport(dir / "calibration.yaml");
  ASSERT_EQ(back.views.size(), names.size());
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(back.views[i].image_name, names[i]);
}

}  // namespace
}  // namespace portcal
