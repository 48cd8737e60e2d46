// Camera calibration from target observations: accuracy on the shared
// renders against their ground truth, agreement with cv::calibrateCamera on
// the same corners of the real in-air set, fixed parameters, and the report.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <opencv2/calib3d.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/stages/camera_calibrator.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

std::vector<CalibrationView> ViewsFromDatabase(const fs::path& path) {
  Database db(path, Database::OpenMode::kReadOnly);
  return ReadTargetViews(&db).by_camera.begin()->second;
}

void Extract(const fs::path& images, const fs::path& database, const std::string& model, int cols,
             int rows, double square) {
  TargetExtractorOptions options;
  options.database_path = database.string();
  options.image_path = images.string();
  options.reader.camera_model = model;
  options.reader.single_camera = true;
  options.chessboard.cols = cols;
  options.chessboard.rows = rows;
  options.square_size_m = square;
  NullProgress progress;
  RunTargetExtractor(options, progress);
}

// The published tool reaches |df| 0.02 px and |dc| 0.13 px on this set;
// portcal must do at least as well, up to 3 of its own standard deviations.
TEST(CameraCalibration, SharedInAirRenderWithinTheGroundTruth) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered/chess_air_distorted";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  Extract(set / "images", dir / "db.db", "RADIAL", 10, 7, 0.02);
  Camera initial = Camera::FromModelName("RADIAL", 1000, 1920, 1080);
  const CameraCalibrationResult result =
      CalibrateCamera(ViewsFromDatabase(dir / "db.db"), initial, {});
  const std::vector<double>& p = result.camera.params;
  const std::vector<double>& t = truth.camera.params;
  const std::vector<double>& s = result.params_std_dev;
  EXPECT_LT(std::abs(p[0] - t[0]), 0.02 + 3 * s[0]);
  EXPECT_LT(std::abs(p[1] - t[1]), 0.13 + 3 * s[1]);
  EXPECT_LT(std::abs(p[2] - t[2]), 0.13 + 3 * s[2]);
  EXPECT_LT(std::abs(p[3] - t[3]), 4 * s[3]);
  EXPECT_LT(std::abs(p[4] - t[4]), 4 * s[4]);
  for (double sd : s) EXPECT_GT(sd, 0);
  EXPECT_LT(result.overall_rms_px, 0.02);
}

// Same corners, same model, same cost: the minimizers agree far inside the
// standard deviations.
TEST(CameraCalibration, RealInAirSetAgreesWithOpenCV) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  Extract(shared / "datasets/real-dome/air", dir / "db.db", "OPENCV", 8, 6, 0.03);
  const std::vector<CalibrationView> views = ViewsFromDatabase(dir / "db.db");
  EXPECT_EQ(views.size(), 19u);  // every view
  const Camera initial = Camera::FromModelName("OPENCV", 2000, 1440, 1080);
  const CameraCalibrationResult ours = CalibrateCamera(views, initial, {});

  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (const CalibrationView& view : views) {
    object_points.emplace_back();
    image_points.emplace_back();
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      object_points.back().emplace_back(view.points_in_target[i].x(), view.points_in_target[i].y(),
                                        0);
      image_points.back().emplace_back(view.pixels[i].x() - 0.5, view.pixels[i].y() - 0.5);
    }
  }
  cv::Mat k, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  const double opencv_rms = cv::calibrateCamera(
      object_points, image_points, cv::Size(1440, 1080), k, distortion, rvecs, tvecs,
      cv::CALIB_FIX_K3,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-14));
  const std::vector<double> opencv = {k.at<double>(0, 0),       k.at<double>(1, 1),
                                      k.at<double>(0, 2) + 0.5, k.at<double>(1, 2) + 0.5,
                                      distortion.at<double>(0), distortion.at<double>(1),
                                      distortion.at<double>(2), distortion.at<double>(3)};
  for (size_t i = 0; i < opencv.size(); ++i) {
    EXPECT_LT(std::abs(ours.camera.params[i] - opencv[i]), ours.params_std_dev[i])
        << "parameter " << i;
  }
  EXPECT_NEAR(ours.overall_rms_px, opencv_rms, 0.01);
}

TEST(CameraCalibration, BoardWarpOnTheRealSet) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  Extract(shared / "datasets/real-dome/air", dir / "db.db", "OPENCV", 8, 6, 0.03);
  const Camera initial = Camera::FromModelName("OPENCV", 2000, 1440, 1080);
  CameraCalibrationSettings flat, warped;
  warped.estimate_board_warp = true;
  const auto views = ViewsFromDatabase(dir / "db.db");
  const CameraCalibrationResult a = CalibrateCamera(views, initial, flat);
  const CameraCalibrationResult b = CalibrateCamera(views, initial, warped);
  // mrcal fits a 0.28 mm sag on these views and its focal length then
  // differs from the flat-board one by ~22 px.
  EXPECT_NEAR(std::abs(b.board_warp.y()), 0.28e-3, 3 * b.board_warp_std_dev.y() + 0.03e-3);
  EXPECT_GT(b.camera.params[0] - a.camera.params[0], 10.0);
  EXPECT_LT(b.overall_rms_px, a.overall_rms_px);
}

TEST(CameraCalibration, FixedParametersStayAndNamesAreChecked) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  Extract(shared / "datasets/rendered/chess_air_distorted/images", dir / "db.db", "RADIAL", 10, 7,
          0.02);
  Camera initial = Camera::FromModelName("RADIAL", 1300, 1920, 1080);
  initial.params[4] = -0.02;
  CameraCalibrationSettings settings;
  settings.fixed_params = {"k2", "principal_point"};
  settings.initialize_from_data = true;
  const CameraCalibrationResult result =
      CalibrateCamera(ViewsFromDatabase(dir / "db.db"), initial, settings);
  EXPECT_EQ(result.camera.params[4], -0.02);
  EXPECT_EQ(result.camera.params[1], 960.0);
  EXPECT_EQ(result.params_std_dev[4], 0.0);
  EXPECT_GT(result.params_std_dev[0], 0.0);
  settings.fixed_params = {"k7"};
  try {
    CalibrateCamera(ViewsFromDatabase(dir / "db.db"), initial, settings);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("k7"), std::string::npos);
  }
}

TEST(CameraCalibration, StageWritesBothReports) {
  PORTCAL_REQUIRE_SHARED(shared);
  testing::TempDir dir;
  Extract(shared / "datasets/rendered/chess_domeport/images", dir / "db.db", "RADIAL", 10, 7, 0.02);
  CameraCalibratorOptions options;
  options.database_path = (dir / "db.db").string();
  options.output_path = (dir / "out").string();
  const std::string database_before = testing::ReadFileToString(dir / "db.db");
  RunCameraCalibrator(options, NoProgress());
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), database_before);  // read only
  const CalibrationReport report = ReadCalibrationReport(dir / "out/calibration.yaml");
  EXPECT_EQ(report.camera.ModelName(), "RADIAL");
  EXPECT_FALSE(report.housing.has_value());
  const std::string text = testing::ReadFileToString(dir / "out/calibration.txt");
  EXPECT_NE(text.find("RMS reprojection error"), std::string::npos);
  EXPECT_NE(text.find("img_025.png"), std::string::npos);
  // The board's sag is fitted by default and said in a note.
  ASSERT_TRUE(report.board_warp.has_value());
  EXPECT_NE(text.find("Note: board warp: sag"), std::string::npos) << text;
  EXPECT_NE(text.find("held flat"), std::string::npos) << text;
  // --update_database: the next stage (portcal's or COLMAP's) starts from
  // the calibration.
  options.update_database = true;
  const CameraCalibrationResult result = RunCameraCalibrator(options, NoProgress());
  Database database(dir / "db.db", Database::OpenMode::kReadOnly);
  const std::vector<Camera> cameras = database.ReadAllCameras();
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].params, result.camera.params);
  EXPECT_TRUE(cameras[0].has_prior_focal_length);
}

TEST(CalibrationReport, NotesAndTargetSurviveQuotesThroughYaml) {
  testing::TempDir dir;
  CalibrationReport report;
  report.camera = Camera::FromModelName("RADIAL", 1000, 1600, 1200);
  report.parameters_std_dev = {1, 0, 0, 0.01, 0.01};
  report.target_description = "the diver's board: 'A3'";
  report.notes = {
      "principal point held at the image centre: refined, it was off by x +0.50 px (sd 0.20)",
      "it's quoted"};
  WriteCalibrationReport(report, dir / "out");
  const CalibrationReport read = ReadCalibrationReport(dir / "out/calibration.yaml");
  EXPECT_EQ(read.notes, report.notes);
  EXPECT_EQ(read.target_description, report.target_description);
  const std::string text = testing::ReadFileToString(dir / "out/calibration.txt");
  EXPECT_NE(text.find("Note: it's quoted"), std::string::npos);
}

// A target observation no detector writes (an edited or damaged row: 9e999
// reads as infinity) is an input error naming the database, the image and
// the point, not a solver that "did not converge".
TEST(CameraCalibration, ANonFiniteObservationNamesTheImageAndPoint) {
  testing::TempDir dir;
  {
    Database database(dir / "db.db", Database::OpenMode::kCreate);
    DatabaseImage image;
    image.name = "view_7.png";
    image.camera_id = database.WriteCamera(Camera::FromModelName("PINHOLE", 500, 640, 480));
    const image_t image_id = database.WriteImage(image);
    std::vector<TargetObservation> rows(3);
    for (int i = 0; i < 3; ++i)
      rows[i] = {i, Eigen::Vector2d(100 + i, 200), Eigen::Vector3d(0.03 * i, 0, 0)};
    database.WriteTargetObservations(image_id, rows);
    database.WriteTargetDetectionStatus(image_id, {"chessboard 3x1", true, 3, ""});
  }
  // portcal refuses to write it; another tool edits the row.
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "db.db").string().c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(raw, "UPDATE portcal_target_observations SET x = 9e999 WHERE point_id = 2;",
                   nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(raw);
  Database database(dir / "db.db", Database::OpenMode::kReadOnly);
  try {
    ReadTargetViews(&database);
    ADD_FAILURE() << "a non-finite observation was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("view_7.png, target point 2"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace portcal
