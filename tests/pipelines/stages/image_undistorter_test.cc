// image_undistorter: a model behind a flat port becomes a COLMAP dense
// workspace (PINHOLE cameras, the same poses, keypoints where the
// undistorted images show them, stereo/ configs); a calibration file and a
// folder become pinhole images, the remap tables (which cv::remap applies
// as portcal did) and the report; bad input names what is wrong and leaves
// the output folder as it was.
#include "pipelines/stages/image_undistorter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "pipelines/calibration/calibration_report.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

Camera LensCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 330, 400, 300);
  camera.camera_id = 1;
  camera.params = {330, 332, 203.5, 146.0, -0.2, 0.05, 0.001, -0.0005};
  return camera;
}

Housing TiltedFlatPort() {
  const double tilt = 3.0 * M_PI / 180.0;
  return Housing::FromName(
      "FLATPORT", {std::sin(tilt), 0, std::cos(tilt), 0.02, 0.01, 1.0, 1.49, 1.334}, "test");
}

// Two images 0.3 m apart looking at points 1.5-2.5 m away, behind the port,
// their files (cluttered scenes) in `dir`/images.
SparseModel WriteModelAndImages(const fs::path& dir, bool with_housing) {
  SparseModel model;
  model.cameras[1] = LensCamera();
  if (with_housing) model.housings[1] = TiltedFlatPort();
  const HousedCamera camera{model.cameras[1],
                            with_housing ? std::optional<Housing>(TiltedFlatPort()) : std::nullopt};
  fs::create_directories(dir / "images" / "left");
  for (image_t id : {1, 2}) {
    Image& image = model.images[id];
    image.image_id = id;
    image.name = "left/im" + std::to_string(id) + ".png";
    image.camera_id = 1;
    image.cam_from_world.translation = Eigen::Vector3d(-0.3 * (id - 1), 0, 0);
    cv::imwrite((dir / "images" / image.name).string(), testing::ClutteredScene(400, 300, id));
  }
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> x(-0.6, 0.9), y(-0.5, 0.5), z(1.5, 2.5);
  for (point3D_t id = 1; id <= 60; ++id) {
    Point3D point;
    point.xyz = Eigen::Vector3d(x(rng), y(rng), z(rng));
    for (auto& [image_id, image] : model.images) {
      const std::optional<Eigen::Vector2d> pixel = camera.Project(image.cam_from_world * point.xyz);
      if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > 400 || pixel->y() > 300)
        continue;
      point.track.push_back({image_id, static_cast<point2D_t>(image.points2D.size())});
      image.points2D.push_back({*pixel, id});
    }
    if (point.track.size() >= 2) {
      model.points3D[id] = point;
    } else {
      for (const TrackElement& element : point.track)
        model.images[element.image_id].points2D.pop_back();
    }
  }
  WriteSparseModel(model, dir / "model", ModelFormat::kText);
  return model;
}

ImageUndistorterOptions Options(const testing::TempDir& dir) {
  ImageUndistorterOptions options;
  options.input_path = (dir / "model").string();
  options.image_path = (dir / "images").string();
  options.output_path = (dir / "out").string();
  return options;
}

TEST(ImageUndistorter, ModelBehindAPortBecomesADenseWorkspace) {
  testing::TempDir dir;
  const SparseModel input = WriteModelAndImages(dir.path(), true);
  const ImageUndistorterSummary summary = RunImageUndistorter(Options(dir), NoProgress());
  ASSERT_EQ(summary.cameras.size(), 1u);
  const CameraUndistortion& camera = summary.cameras[0];
  // Without depth options: the points' depths (1.5-2.5 m, seen from two places).
  EXPECT_GT(camera.range.near, 1.4);
  EXPECT_LT(camera.range.far, 2.6);
  EXPECT_GT(camera.pinhole.design_depth, camera.range.near);
  EXPECT_LT(camera.pinhole.design_depth, camera.range.far);

  const SparseModel output = ReadSparseModel(dir / "out" / "sparse");
  ASSERT_EQ(output.cameras.size(), 1u);
  EXPECT_EQ(output.cameras.at(1).ModelName(), "PINHOLE");
  EXPECT_TRUE(output.housings.empty());
  ASSERT_EQ(output.images.size(), 2u);
  EXPECT_EQ(output.points3D.size(), input.points3D.size());
  for (const auto& [id, image] : output.images) {
    EXPECT_LT(
        (image.cam_from_world.translation - input.images.at(id).cam_from_world.translation).norm(),
        1e-12);
    const cv::Mat undistorted =
        cv::imread((dir / "out" / "images" / image.name).string(), cv::IMREAD_UNCHANGED);
    EXPECT_EQ(undistorted.cols, static_cast<int>(output.cameras.at(1).width));
    EXPECT_EQ(undistorted.rows, static_cast<int>(output.cameras.at(1).height));
    // Each keypoint is where the pinhole projects its point, within the
    // approximation's worst error over the range.
    for (const Point2D& point2D : image.points2D) {
      const Eigen::Vector3d point =
          image.cam_from_world * output.points3D.at(point2D.point3D_id).xyz;
      const Eigen::Vector2d projected = *camera.pinhole.PinholePixel(point);
      EXPECT_LT((projected - point2D.xy).norm(), camera.error.worst_px + 1e-6);
    }
  }
  const std::string patch_match =
      testing::ReadFileToString(dir / "out" / "stereo" / "patch-match.cfg");
  EXPECT_EQ(patch_match, "left/im1.png\n__auto__, 20\nleft/im2.png\n__auto__, 20\n");
  EXPECT_EQ(testing::ReadFileToString(dir / "out" / "stereo" / "fusion.cfg"),
            "left/im1.png\nleft/im2.png\n");
  EXPECT_TRUE(fs::is_directory(dir / "out" / "stereo" / "depth_maps" / "left"));
  EXPECT_TRUE(fs::exists(dir / "out" / "run-colmap-geometric.sh"));
  EXPECT_TRUE(fs::exists(dir / "out" / "report" / "report.html"));
  EXPECT_FALSE(fs::exists(dir / "out" / ".image_undistorter_staging"));
  const std::string text = testing::ReadFileToString(dir / "out" / "undistortion.txt");
  EXPECT_NE(text.find("design depth"), std::string::npos) << text;
}

TEST(ImageUndistorter, CalibrationFileGivesImagesMapsAndWarnings) {
  testing::TempDir dir;
  WriteModelAndImages(dir.path(), false);
  CalibrationReport report;
  report.camera = LensCamera();
  report.housing = TiltedFlatPort();
  WriteCalibrationReport(report, dir / "cal");
  ImageUndistorterOptions options = Options(dir);
  options.input_path = (dir / "cal" / "calibration.yaml").string();
  options.depth_range = {0.5, 5.0};
  options.write_maps = true;
  const ImageUndistorterSummary summary = RunImageUndistorter(options, NoProgress());
  EXPECT_EQ(summary.num_images, 2u);
  // A flat port over a decade of depths: pixels of error, said loudly.
  ASSERT_EQ(summary.warnings.size(), 1u);
  EXPECT_NE(summary.warnings[0].find("camera 1"), std::string::npos);
  EXPECT_NE(testing::ReadFileToString(dir / "out" / "undistortion.txt").find("WARNING"),
            std::string::npos);
  // The tables, read as a robot would, undistort as portcal did.
  cv::FileStorage storage((dir / "out" / "maps" / "camera_1.yaml.gz").string(),
                          cv::FileStorage::READ);
  ASSERT_TRUE(storage.isOpened());
  cv::Mat map_x, map_y;
  storage["map_x"] >> map_x;
  storage["map_y"] >> map_y;
  ASSERT_EQ(map_x.type(), CV_32FC1);
  const cv::Mat source =
      cv::imread((dir / "images" / "left" / "im1.png").string(), cv::IMREAD_UNCHANGED);
  cv::Mat by_robot;
  cv::remap(source, by_robot, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  const cv::Mat by_portcal =
      cv::imread((dir / "out" / "images" / "left" / "im1.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(by_robot.size(), by_portcal.size());
  cv::Mat difference;
  cv::absdiff(by_robot, by_portcal, difference);
  double largest = 0;
  cv::minMaxLoc(difference.reshape(1), nullptr, &largest);
  EXPECT_EQ(largest, 0.0);  // the same tables, the same cv::remap
  // No poses: the camera alone in sparse/.
  const SparseModel model = ReadSparseModel(dir / "out" / "sparse");
  EXPECT_EQ(model.cameras.size(), 1u);
  EXPECT_TRUE(model.images.empty());
}

TEST(ImageUndistorter, InAirModelNeedsNoDepths) {
  testing::TempDir dir;
  SparseModel model = WriteModelAndImages(dir.path(), false);
  model.points3D.clear();
  for (auto& [id, image] : model.images) image.points2D.clear();
  WriteSparseModel(model, dir / "model", ModelFormat::kText);
  const ImageUndistorterSummary summary = RunImageUndistorter(Options(dir), NoProgress());
  EXPECT_LT(summary.cameras[0].error.worst_px, 1e-6);
  EXPECT_TRUE(summary.warnings.empty());
}

// A stereo_calibrator file (the keys image_undistorter reads) of two
// lenses behind flat ports, 10 cm apart.
void WriteStereoCalibration(const fs::path& path) {
  std::ofstream out(path);
  out << "cam2_from_cam1:\n  rotation_wxyz: [0.99996, 0.0, 0.00873, 0.0]\n  translation: [-0.1, "
         "0.001, 0.0]\n";
  for (const char* key : {"camera1", "camera2"}) {
    out << key
        << ":\n  model: OPENCV\n  parameters: [330, 332, 203.5, 146.0, -0.2, 0.05, 0.001, "
           "-0.0005]\n"
        << "  non_svp_model: FLATPORT\n  non_svp_parameters: [0, 0, 1, 0.02, 0.01, 1.0, 1.49, "
           "1.334]\n"
        << "  width: 400\n  height: 300\n";
  }
}

TEST(ImageUndistorter, StereoCalibrationGivesRectifiedPairs) {
  testing::TempDir dir;
  for (const char* folder : {"cam1", "cam2"}) {
    fs::create_directories(dir / "rig" / folder);
    cv::imwrite((dir / "rig" / folder / "frame_01.png").string(),
                testing::ClutteredScene(400, 300, 4));
  }
  WriteStereoCalibration(dir / "stereo.yaml");
  ImageUndistorterOptions options = Options(dir);
  options.input_path = (dir / "stereo.yaml").string();
  options.image_path = (dir / "rig").string();
  options.distance = 1.5;
  const ImageUndistorterSummary summary = RunImageUndistorter(options, NoProgress());
  ASSERT_EQ(summary.cameras.size(), 2u);
  EXPECT_EQ(summary.cameras[0].stereo_partner, 2u);
  EXPECT_NEAR(summary.cameras[1].rectified_baseline, std::hypot(0.1, 0.001), 1e-3);
  const SparseModel model = ReadSparseModel(dir / "out" / "sparse");
  ASSERT_EQ(model.cameras.size(), 2u);
  EXPECT_EQ(model.cameras.at(1).params[1], model.cameras.at(2).params[1]);  // one fy
  EXPECT_EQ(model.cameras.at(1).params[3], model.cameras.at(2).params[3]);  // one principal row
  const cv::Mat left = cv::imread((dir / "out" / "images" / "cam1" / "frame_01.png").string());
  const cv::Mat right = cv::imread((dir / "out" / "images" / "cam2" / "frame_01.png").string());
  EXPECT_EQ(left.rows, right.rows);
  EXPECT_NE(testing::ReadFileToString(dir / "out" / "undistortion.txt")
                .find("rectified with camera 2: baseline 0.1000 m"),
            std::string::npos);
  // One folder of images cannot be a rig's.
  options.image_path = (dir / "rig" / "cam1").string();
  EXPECT_THROW(RunImageUndistorter(options, NoProgress()), InputError);
}

// Runs a failing undistortion over an output folder holding a previous
// result: the error names `expected`, the folder is as it was.
void ExpectFailureNaming(const ImageUndistorterOptions& options, const std::string& expected) {
  const fs::path out(options.output_path);
  fs::create_directories(out);
  std::ofstream(out / "previous.txt") << "kept";
  try {
    RunImageUndistorter(options, NoProgress());
    ADD_FAILURE() << "no error; expected one naming " << expected;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(out))
    left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"previous.txt"});
}

TEST(ImageUndistorter, BadInputNamesWhatIsWrongAndWritesNothing) {
  testing::TempDir dir;
  WriteModelAndImages(dir.path(), true);
  ImageUndistorterOptions options = Options(dir);
  // A depth range inside the housing (the port's glass ends ~31 mm out).
  options.depth_range = {0.02, 2.0};
  ExpectFailureNaming(options, "--Undistort.depth_range: 0.02 m is inside camera 1's housing");
  options.depth_range = {};
  // An image missing from the folder.
  fs::rename(dir / "images" / "left" / "im2.png", dir / "im2.png");
  ExpectFailureNaming(options, "left/im2.png: no such image");
  fs::rename(dir / "im2.png", dir / "images" / "left" / "im2.png");
  // An image of another size than its camera.
  cv::imwrite((dir / "images" / "left" / "im2.png").string(), testing::ClutteredScene(320, 240, 2));
  ExpectFailureNaming(options, "left/im2.png: the image is 320 x 240 px, its camera 400 x 300");
  // housings.txt naming a camera the model does not have.
  std::ofstream(dir / "model" / "housings.txt", std::ios::app)
      << "7 FLATPORT 0 0 1 0.02 0.01 1 1.49 1.334\n";
  ExpectFailureNaming(options, "housings.txt");
  // A calibration file behind a port with no depths to go by.
  CalibrationReport report;
  report.camera = LensCamera();
  report.housing = TiltedFlatPort();
  WriteCalibrationReport(report, dir / "cal");
  options.input_path = (dir / "cal" / "calibration.yaml").string();
  ExpectFailureNaming(options, "give --Undistort.distance or --Undistort.depth_range");
}

TEST(ImageUndistorter, OptionsOutOfRangeAreNamed) {
  ImageUndistorterOptions options;
  options.input_path = "m";
  options.image_path = "i";
  options.output_path = "o";
  options.field_of_view.blank_pixels = 1.5;
  EXPECT_THROW(options.Check(), OptionError);
  options.field_of_view.blank_pixels = 0;
  options.depth_range = {2.0, 0.0};
  EXPECT_THROW(options.Check(), OptionError);
  options.depth_range = {};
  options.distance = -1;
  EXPECT_THROW(options.Check(), OptionError);
}

}  // namespace
}  // namespace portcal
