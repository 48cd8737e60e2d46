// target_extractor: chessboard corners in the database where the ground
// truth says they are (portcal's detector: median <= 0.005 px, max <= 0.05
// px on the shared renders in air and behind both ports), per-image outcome,
// reruns, and a failed run that leaves the database as it was.
#include "pipelines/stages/target_extractor.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/stages/synthesize.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

TargetExtractorOptions Options(const fs::path& database, const fs::path& images) {
  TargetExtractorOptions options;
  options.database_path = database.string();
  options.image_path = images.string();
  options.reader.camera_model = "RADIAL";
  options.reader.single_camera = true;
  return options;
}

// A plain image of the default board (10 x 7 inner corners: 11 x 8 squares)
// filling most of it, for the tests of what the reader does with files: a
// run that finds the target in no image is an error.
cv::Mat BoardImage(int width, int height) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(230));
  const int square = std::min((width - 16) / 11, (height - 16) / 8);
  const int x0 = (width - 11 * square) / 2, y0 = (height - 8 * square) / 2;
  for (int r = 0; r < 8; ++r) {
    for (int c = 0; c < 11; ++c) {
      if ((r + c) % 2 == 0)
        cv::rectangle(image, cv::Rect(x0 + c * square, y0 + r * square, square, square), 20,
                      cv::FILLED);
    }
  }
  return image;
}

// Errors (px) of the stored observations against the ground truth.
std::vector<double> ObservationErrors(const fs::path& database, const GroundTruth& truth) {
  Database db(database, Database::OpenMode::kReadOnly);
  std::vector<double> errors;
  for (const FrameTruth& frame : truth.images) {
    const std::string name = fs::path(frame.cam1.file).filename().string();
    const auto image = db.ReadImageWithName(name);
    EXPECT_TRUE(image.has_value()) << name;
    if (!image) continue;
    const auto status = db.ReadTargetDetectionStatus(image->image_id);
    EXPECT_TRUE(status && status->found) << name << ": " << (status ? status->reason : "no status");
    for (const TargetObservation& o : db.ReadTargetObservations(image->image_id)) {
      EXPECT_LT((o.point_in_target - truth.target.corners_3d[o.point_id]).norm(), 1e-12);
      errors.push_back((o.xy - *frame.cam1.corners_px[o.point_id]).norm());
    }
  }
  std::sort(errors.begin(), errors.end());
  return errors;
}

class SharedSets : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedSets, CornersWithinHundredthsOfAPixel) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered" / GetParam();
  if (!fs::exists(set / "ground_truth.yaml")) GTEST_SKIP() << set << " absent";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  NullProgress progress;
  const TargetExtractorSummary summary =
      RunTargetExtractor(Options(dir / "db.db", set / "images"), progress);
  EXPECT_EQ(summary.num_found, 25);
  const std::vector<double> errors = ObservationErrors(dir / "db.db", truth);
  ASSERT_EQ(errors.size(), 25u * 70u);
  std::cout << GetParam() << ": median " << errors[errors.size() / 2] << " px, max "
            << errors.back() << " px\n";
  EXPECT_LE(errors[errors.size() / 2], 0.005) << GetParam();
  EXPECT_LE(errors.back(), 0.05) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Rendered, SharedSets,
                         ::testing::Values("chess_air_distorted", "chess_domeport",
                                           "chess_flatport"));

TEST(TargetExtractor, ReportsImagesWithoutTheBoardAndRerunsCleanly) {
  testing::TempDir dir;
  std::ofstream(dir / "set.yaml") << R"(name: small
seed: 4
num_images: 3
camera: {model: RADIAL, width: 800, height: 600, params: [700.0, 400.0, 300.0, -0.05, 0.0]}
housing: null
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.4, 0.8], tilt_max_deg: 35}
)";
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  cv::imwrite((dir / "set/images/zz_empty.png").string(),
              cv::Mat(600, 800, CV_8UC1, cv::Scalar(120)));

  TargetExtractorOptions options = Options(dir / "db.db", dir / "set/images");
  options.chessboard.cols = 8;
  options.chessboard.rows = 6;
  options.square_size_m = 0.025;
  const TargetExtractorSummary first = RunTargetExtractor(options, progress);
  EXPECT_EQ(first.num_images, 4);
  EXPECT_EQ(first.num_found, 3);
  const TargetExtractorSummary second = RunTargetExtractor(options, progress);
  EXPECT_EQ(second.num_points, first.num_points);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(db.NumImages(), 4);
  EXPECT_EQ(db.NumCameras(), 1);  // single_camera
  const auto empty = db.ReadImageWithName("zz_empty.png");
  ASSERT_TRUE(empty.has_value());
  const auto status = db.ReadTargetDetectionStatus(empty->image_id);
  ASSERT_TRUE(status.has_value());
  EXPECT_FALSE(status->found);
  EXPECT_NE(status->reason.find("no 8x6"), std::string::npos) << status->reason;
  EXPECT_EQ(db.ReadStageLog().size(), 2u);
}

// A rerun with other reader options meets the cameras of the first run:
// an error naming the difference and the way out, the database untouched;
// with --ImageReader.overwrite the cameras are imported again and the old
// ones are gone.
TEST(TargetExtractor, ARerunWithOtherReaderOptionsSaysSoOrImportsTheCamerasAgain) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  for (const char* name : {"a.png", "b.png", "c.png"}) {
    cv::imwrite((dir / "images" / name).string(), BoardImage(160, 120));
  }
  NullProgress progress;
  TargetExtractorOptions first = Options(dir / "db.db", dir / "images");
  first.reader.camera_model = "SIMPLE_RADIAL";
  first.reader.single_camera = false;  // COLMAP's default: a camera per image
  RunTargetExtractor(first, progress);
  const std::string before = testing::ReadFileToString(dir / "db.db");

  TargetExtractorOptions second = Options(dir / "db.db", dir / "images");
  second.reader.camera_model = "OPENCV";
  try {
    RunTargetExtractor(second, progress);
    FAIL() << "a rerun with other reader options went through";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("a.png"), std::string::npos) << what;
    EXPECT_NE(what.find("SIMPLE_RADIAL"), std::string::npos) << what;
    EXPECT_NE(what.find("--ImageReader.overwrite 1"), std::string::npos) << what;
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);
  second.reader.camera_model = "SIMPLE_RADIAL";  // the model agrees, the sharing does not
  EXPECT_THROW(RunTargetExtractor(second, progress), InputError);
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);

  second.reader.camera_model = "OPENCV";
  second.reader.overwrite = true;
  RunTargetExtractor(second, progress);
  {
    Database db(dir / "db.db", Database::OpenMode::kReadOnly);
    ASSERT_EQ(db.NumCameras(), 1);
    EXPECT_EQ(db.ReadAllCameras().front().ModelName(), "OPENCV");
    EXPECT_EQ(db.NumImages(), 3);
    for (const DatabaseImage& image : db.ReadAllImages()) {
      EXPECT_EQ(image.camera_id, db.ReadAllCameras().front().camera_id) << image.name;
    }
  }
  // A new image, first in name order, joins the shared camera of the
  // images already there: no second camera, no error.
  cv::imwrite((dir / "images/0_first.png").string(), cv::Mat(120, 160, CV_8UC1, cv::Scalar(90)));
  second.reader.overwrite = false;
  RunTargetExtractor(second, progress);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  EXPECT_EQ(db.NumCameras(), 1);
  EXPECT_EQ(db.NumImages(), 4);
}

// A folder of links to images elsewhere (as a benchmark or a selection
// makes): the images are named by their links, as COLMAP names them.
TEST(TargetExtractor, SymlinkedImagesKeepTheirLinksNames) {
  testing::TempDir dir;
  fs::create_directories(dir / "elsewhere");
  fs::create_directories(dir / "images");
  cv::imwrite((dir / "elsewhere/original.png").string(), BoardImage(200, 100));
  fs::create_symlink(dir / "elsewhere/original.png", dir / "images/link.png");
  NullProgress progress;
  RunTargetExtractor(Options(dir / "db.db", dir / "images"), progress);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  EXPECT_TRUE(db.ReadImageWithName("link.png").has_value());
}

TEST(TargetExtractor, AFailedRunLeavesTheDatabaseAsItWas) {
  testing::TempDir dir;
  fs::create_directories(dir / "images");
  cv::imwrite((dir / "images/a.png").string(), cv::Mat(100, 200, CV_8UC1, cv::Scalar(0)));
  cv::imwrite((dir / "images/b.png").string(), cv::Mat(120, 200, CV_8UC1, cv::Scalar(0)));
  { Database db(dir / "db.db", Database::OpenMode::kCreate); }
  const std::string before = testing::ReadFileToString(dir / "db.db");
  NullProgress progress;
  // Two image sizes with one shared camera: b.png is at fault.
  try {
    RunTargetExtractor(Options(dir / "db.db", dir / "images"), progress);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.png"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);
  TargetExtractorOptions bad = Options(dir / "db.db", dir / "images");
  bad.reader.camera_params = "1, 2";
  try {
    RunTargetExtractor(bad, progress);
    FAIL() << "expected OptionError";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--ImageReader.camera_params"), std::string::npos);
  }
  EXPECT_EQ(testing::ReadFileToString(dir / "db.db"), before);
  // A database the failed run created is not left behind.
  EXPECT_THROW(RunTargetExtractor(Options(dir / "new.db", dir / "images"), progress), InputError);
  EXPECT_FALSE(fs::exists(dir / "new.db"));
  EXPECT_FALSE(fs::exists(dir / "new.db-journal"));
  // A database that cannot be one fails before any image is read.
  fs::create_directories(dir / "folder.db");
  try {
    RunTargetExtractor(Options(dir / "folder.db", dir / "images"), progress);
    FAIL() << "expected DatabaseError";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("folder.db"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace portcal

namespace portcal {
namespace {

// ArUco grid and ChArUco boards: observations where the ground truth puts
// them (ChArUco corners refined to hundredths of a pixel, marker corners to
// OpenCV's contour fit), and a camera calibration from them within its
// standard deviations of the truth.
class MarkerBoards : public ::testing::TestWithParam<std::string> {};

TEST_P(MarkerBoards, ObservationsAndCalibration) {
  testing::TempDir dir;
  const bool charuco = GetParam() == "charuco";
  std::ofstream(dir / "set.yaml")
      << "name: boards\nseed: 12\nnum_images: 10\n"
      << "camera: {model: RADIAL, width: 800, height: 600, params: [650.0, 401.0, 299.0, -0.08, "
         "0.01]}\n"
      << "housing: null\n"
      << (charuco ? "target: {type: charuco, squares_x: 7, squares_y: 5, square_size: 0.03, "
                    "marker_size: 0.022}\n"
                  : "target: {type: aruco_grid, markers_x: 5, markers_y: 4, marker_size: 0.03, "
                    "marker_separation: 0.008}\n")
      << "poses: {distance: [0.35, 0.8], tilt_max_deg: 40, roll_max_deg: 40}\n";
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "set.yaml").string();
  synthesize.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  const GroundTruth truth = ReadGroundTruth(dir / "set/ground_truth.yaml");

  TargetExtractorOptions options = Options(dir / "db.db", dir / "set/images");
  options.target_type = GetParam();
  options.square_size_m = 0.03;
  options.markers.markers_x = 5;
  options.markers.markers_y = 4;
  options.markers.marker_size_m = charuco ? 0.022 : 0.03;
  options.markers.marker_separation_m = 0.008;
  options.markers.squares_x = 7;
  options.markers.squares_y = 5;
  const TargetExtractorSummary summary = RunTargetExtractor(options, progress);
  EXPECT_EQ(summary.num_found, 10);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  std::vector<double> errors;
  for (const FrameTruth& frame : truth.images) {
    const auto image = db.ReadImageWithName(fs::path(frame.cam1.file).filename().string());
    ASSERT_TRUE(image.has_value());
    EXPECT_FALSE(db.ReadMarkerDetections(image->image_id).empty());
    for (const TargetObservation& o : db.ReadTargetObservations(image->image_id)) {
      if (charuco) {
        errors.push_back((o.xy - *frame.cam1.corners_px[o.point_id]).norm());
      } else {
        for (const auto& marker : frame.cam1.markers) {
          if (marker.id == o.point_id / 4)
            errors.push_back((o.xy - marker.corners_px[o.point_id % 4]).norm());
        }
      }
    }
  }
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  // ChArUco: the ideal-pattern fit, in windows that must stay inside the
  // white margins around the markers (~4 px here against ~10 px on a
  // chessboard, so ~2.5x the chessboard's worst case). ArUco grid: the
  // marker outline's edges fitted to the pixels (OpenCV's contour corners
  // alone: a median of ~0.6 px, their bias); issue 24's goal of 0.02 px.
  std::cout << GetParam() << ": median " << errors[errors.size() / 2] << " px, max "
            << errors.back() << " px\n";
  EXPECT_LT(errors[errors.size() / 2], 0.02) << GetParam();
  EXPECT_LT(errors.back(), charuco ? 0.3 : 0.5) << GetParam();
  const CameraCalibrationResult result =
      CalibrateCamera(ReadTargetViews(&db).by_camera.begin()->second,
                      Camera::FromModelName("RADIAL", 700, 800, 600), {});
  std::cout << GetParam() << ": parameters off by";
  for (int i = 0; i < 5; ++i) {
    std::cout << " "
              << (result.camera.params[i] - truth.camera.params[i]) / result.params_std_dev[i];
    EXPECT_LT(std::abs(result.camera.params[i] - truth.camera.params[i]),
              4 * result.params_std_dev[i] + 1e-9)
        << "parameter " << i;
  }
  std::cout << " sigma\n";
}

INSTANTIATE_TEST_SUITE_P(Targets, MarkerBoards, ::testing::Values("aruco_grid", "charuco"));

// ArUco grids seen close, steeply and cut by the image's border: markers
// whose edges cannot be fitted give no observations, and each image's
// status counts them (4 corners per marker detected, kept or left out).
TEST(MarkerBoardsLeftOut, TheStatusCountsTheMarkerCornersLeftOut) {
  testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(
      dir,
      "name: close\nseed: 7\nnum_images: 8\n"
      "camera: {model: RADIAL, width: 800, height: 600, params: [650.0, 402.0, 298.0, -0.08, "
      "0.01]}\n"
      "housing: null\n"
      "target: {type: aruco_grid, markers_x: 5, markers_y: 4, marker_size: 0.03, "
      "marker_separation: 0.008}\n"
      "poses: {distance: [0.25, 0.5], tilt_max_deg: 65, roll_max_deg: 40, visibility: any}\n"
      "render: {spp: 4, blur_sigma: 0.8, noise_sigma: 2.0}\n");
  TargetExtractorOptions options = Options(dir / "db.db", dir / "set/images");
  options.target_type = "aruco_grid";
  options.markers.markers_x = 5;
  options.markers.markers_y = 4;
  options.markers.marker_size_m = 0.03;
  options.markers.marker_separation_m = 0.008;
  RunTargetExtractor(options, NoProgress());
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  int with_note = 0;
  for (const FrameTruth& frame : truth.images) {
    const auto image = db.ReadImageWithName(fs::path(frame.cam1.file).filename().string());
    ASSERT_TRUE(image.has_value());
    const auto status = db.ReadTargetDetectionStatus(image->image_id);
    ASSERT_TRUE(status && status->found) << frame.cam1.file;
    const int detected = static_cast<int>(db.ReadMarkerDetections(image->image_id).size());
    const int kept = static_cast<int>(db.ReadTargetObservations(image->image_id).size());
    EXPECT_EQ(kept % 4, 0);
    if (kept == 4 * detected) {
      EXPECT_EQ(status->reason, "found") << frame.cam1.file;
      continue;
    }
    ++with_note;
    const int left_out = 4 * detected - kept, markers = left_out / 4;
    const std::string expected = "found; " + std::to_string(left_out) + " of " +
                                 std::to_string(4 * detected) + " marker corners left out (" +
                                 std::to_string(markers) +
                                 (markers == 1 ? " marker too" : " markers too");
    EXPECT_EQ(status->reason.rfind(expected, 0), 0u) << status->reason << " / " << expected;
  }
  // 4 of these 8 views have markers too close to the border or too
  // foreshortened for their edges to be fitted.
  EXPECT_GE(with_note, 2);
}

}  // namespace
}  // namespace portcal
