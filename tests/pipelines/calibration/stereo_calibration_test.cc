// Stereo calibration: the shared in-air stereo render against its ground
// truth, OpenCV's stereo sample against cv::stereoCalibrate on the same
// corners, the robust median, a camera mounted upside down, and a rig
// behind two housings.
#include "pipelines/calibration/stereo_calibration.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <random>

#include "colmap_ext/io/ground_truth.h"
#include "database/database.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/stages/stereo_calibrator.h"
#include "pipelines/stages/synthesize.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

void Extract(const fs::path& images, const fs::path& database, const std::string& model, int cols,
             int rows, double square) {
  TargetExtractorOptions options;
  options.database_path = database.string();
  options.image_path = images.string();
  options.reader.camera_model = model;
  options.reader.single_camera_per_folder = true;
  options.chessboard.cols = cols;
  options.chessboard.rows = rows;
  options.square_size_m = square;
  NullProgress progress;
  RunTargetExtractor(options, progress);
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180 / M_PI;
}

TEST(StereoCalibration, SharedInAirRigWithinItsStandardDeviations) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path set = shared / "datasets/rendered/chess_stereo_air";
  const GroundTruth truth = ReadGroundTruth(set / "ground_truth.yaml");
  testing::TempDir dir;
  Extract(set / "images", dir / "db.db", "RADIAL", 10, 7, 0.02);
  StereoCalibratorOptions options;
  options.database_path = (dir / "db.db").string();
  options.output_path = (dir / "out").string();
  options.stereo.refine_intrinsics = true;
  const StereoCalibrationResult result = RunStereoCalibrator(options, NoProgress());
  const Rigid3d& t = truth.stereo->cam2_from_cam1;
  const Eigen::Vector3d dt = result.cam2_from_cam1.translation - t.translation;
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(result.translation_std_dev[i], 0);
    EXPECT_LT(std::abs(dt[i]), 4 * result.translation_std_dev[i] + 1e-6) << "axis " << i;
  }
  EXPECT_LT(AngleDeg(result.cam2_from_cam1.rotation, t.rotation),
            4 * result.rotation_std_dev_deg.norm() + 1e-4);
  // The median start is already close.
  EXPECT_LT((result.median_cam2_from_cam1.translation - t.translation).norm(), 1e-3);
  EXPECT_TRUE(fs::exists(dir / "out/calibration.yaml"));
  EXPECT_NE(testing::ReadFileToString(dir / "out/calibration.yaml")
                .find("cam_to_world_rotation_rowmajor"),
            std::string::npos);
}

TEST(StereoCalibration, OpenCVStereoSampleAgreesWithStereoCalibrate) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path sample = shared / "datasets/opencv-stereo";
  testing::TempDir dir;
  fs::create_directories(dir / "images/left");
  fs::create_directories(dir / "images/right");
  for (const auto& entry : fs::directory_iterator(sample)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("left", 0) == 0) fs::copy(entry.path(), dir / "images/left" / name.substr(4));
    if (name.rfind("right", 0) == 0) fs::copy(entry.path(), dir / "images/right" / name.substr(5));
  }
  Extract(dir / "images", dir / "db.db", "OPENCV", 9, 6, 0.025);
  StereoCalibratorOptions options;
  options.database_path = (dir / "db.db").string();
  options.output_path = (dir / "out").string();
  options.stereo.refine_intrinsics = true;
  const StereoCalibrationResult ours = RunStereoCalibrator(options, NoProgress());
  // OpenCV's own sample: 13 frames, each camera's corners over half its
  // image, RMS 0.17 px: OK, first in calibration.txt.
  EXPECT_EQ(testing::ReadFileToString(dir / "out/calibration.txt").find("Verdict: OK\n"),
            testing::ReadFileToString(dir / "out/calibration.txt").find("Verdict:"));
  EXPECT_NE(testing::ReadFileToString(dir / "out/calibration.txt").find("Verdict:"),
            std::string::npos);
  const YAML::Node verdict = YAML::LoadFile((dir / "out/calibration.yaml").string())["verdict"];
  EXPECT_EQ(verdict["status"].as<std::string>(), "OK");
  bool camera2_coverage = false;
  for (const YAML::Node& finding : verdict["findings"]) {
    camera2_coverage =
        camera2_coverage || finding["rule"].as<std::string>() == "coverage, camera 2";
  }
  EXPECT_TRUE(camera2_coverage) << "the rule names with commas read back";

  // OpenCV on exactly the same corners and frames.
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  std::map<std::string, std::vector<TargetObservation>> left, right;
  for (const DatabaseImage& image : db.ReadAllImages()) {
    const auto status = db.ReadTargetDetectionStatus(image.image_id);
    if (!status || !status->found) continue;
    const std::string frame = fs::path(image.name).filename().string();
    (image.name.rfind("left", 0) == 0 ? left : right)[frame] =
        db.ReadTargetObservations(image.image_id);
  }
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> points1, points2;
  for (const auto& [frame, observations] : left) {
    if (!right.count(frame)) continue;
    std::map<int64_t, Eigen::Vector2d> in_right;
    for (const auto& o : right[frame]) in_right[o.point_id] = o.xy;
    object.emplace_back();
    points1.emplace_back();
    points2.emplace_back();
    for (const auto& o : observations) {
      if (!in_right.count(o.point_id)) continue;
      object.back().emplace_back(o.point_in_target.x(), o.point_in_target.y(), 0);
      points1.back().emplace_back(o.xy.x() - 0.5, o.xy.y() - 0.5);
      points2.back().emplace_back(in_right[o.point_id].x() - 0.5, in_right[o.point_id].y() - 0.5);
    }
  }
  ASSERT_GE(object.size(), 10u);
  cv::Mat k1, d1, k2, d2, r, t, e, f;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 300, 1e-14);
  const double rms =
      cv::stereoCalibrate(object, points1, points2, k1, d1, k2, d2, cv::Size(640, 480), r, t, e, f,
                          cv::CALIB_FIX_K3, criteria);
  cv::Matx33d rotation;
  r.copyTo(rotation);
  const Eigen::Matrix3d opencv_rotation =
      (Eigen::Matrix3d() << rotation(0, 0), rotation(0, 1), rotation(0, 2), rotation(1, 0),
       rotation(1, 1), rotation(1, 2), rotation(2, 0), rotation(2, 1), rotation(2, 2))
          .finished();
  const Eigen::Vector3d opencv_translation(t.at<double>(0), t.at<double>(1), t.at<double>(2));
  // OpenCV's R, T map camera 1 to camera 2, as cam2_from_cam1 does.
  EXPECT_LT(AngleDeg(ours.cam2_from_cam1.rotation, Eigen::Quaterniond(opencv_rotation)),
            ours.rotation_std_dev_deg.norm());
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(ours.cam2_from_cam1.translation[i] - opencv_translation[i]),
              ours.translation_std_dev[i])
        << "axis " << i;
  }
  EXPECT_NEAR(ours.overall_rms_px, rms, 0.02);
}

TEST(StereoCalibration, MedianIgnoresAFlippedFrame) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 9; ++i) {
    poses.emplace_back(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.05 + 1e-4 * i, Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(-0.1 + 1e-5 * i, 0, 0.005));
  }
  poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(0.3, 0.2, 0.1));  // a view detected rotated by 180 deg
  const Rigid3d median = MedianPose(poses);
  EXPECT_LT(median.rotation.angularDistance(poses[4].rotation), 1e-3);
  EXPECT_LT((median.translation - poses[4].translation).norm(), 1e-4);
}

// A symmetric board (8 x 6 squares) numbered as OpenCV numbers it, from
// the corner nearer the image's top left, by a rig whose camera 2 is
// mounted upside down: camera 2 numbers every frame's board from the other
// end. The start must find the half turn in every frame, not follow the
// majority of wrongly numbered views.
TEST(StereoCalibration, CameraUpsideDownNumbersEveryBoardFromTheOtherEnd) {
  const Camera camera = Camera::FromModelName("PINHOLE", 650, 800, 600);
  const HousedCamera housed{camera, std::nullopt};
  const Rigid3d truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(-4 * M_PI / 180, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(-0.12, 0, 0.004));
  std::vector<Eigen::Vector3d> board;
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 7; ++i) board.emplace_back(0.025 * i, 0.025 * j, 0);
  }
  const Eigen::Vector3d centre(0.075, 0.05, 0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::normal_distribution<double> noise(0, 0.2);
  // The view of one camera, numbered from the corner nearer the image's top
  // left; true if that is the board's other end.
  const auto view_of = [&](const Rigid3d& cam_from_target, const std::string& name,
                           CalibrationView* view) {
    view->image_name = name;
    for (const Eigen::Vector3d& p : board) {
      const auto pixel = housed.Project(cam_from_target * p);
      EXPECT_TRUE(pixel && pixel->x() > 0 && pixel->x() < 800 && pixel->y() > 0 && pixel->y() < 600)
          << name;
      view->pixels.push_back(pixel.value_or(Eigen::Vector2d::Zero()) +
                             Eigen::Vector2d(noise(rng), noise(rng)));
    }
    const bool other_end = view->pixels.front().sum() > view->pixels.back().sum();
    view->points_in_target = board;
    if (other_end)
      std::reverse(view->pixels.begin(), view->pixels.end());  // corner k is now board[n - 1 - k]
    return other_end;
  };
  std::vector<StereoFrame> frames;
  int numbered_differently = 0;
  for (int f = 0; f < 10; ++f) {
    const Eigen::Vector3d tilt_axis(uniform(rng), uniform(rng), 0);
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(35 * M_PI / 180 * uniform(rng), tilt_axis.normalized()) *
        Eigen::AngleAxisd(20 * M_PI / 180 * uniform(rng), Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d centre_in_cam1(-0.06 + 0.05 * uniform(rng), 0.03 * uniform(rng),
                                         0.75 + 0.2 * uniform(rng));
    const Rigid3d cam1_from_target(rotation, centre_in_cam1 - rotation * centre);
    StereoFrame frame;
    const bool end1 = view_of(cam1_from_target, "left/" + std::to_string(f), &frame.cam1);
    const bool end2 = view_of(truth * cam1_from_target, "right/" + std::to_string(f), &frame.cam2);
    numbered_differently += end1 != end2;
    frames.push_back(std::move(frame));
  }
  ASSERT_EQ(numbered_differently, 10);
  const StereoCalibrationResult result =
      CalibrateStereo(frames, housed, housed, StereoCalibrationSettings());
  // 0.2 px of noise on 35 corners a view, 10 frames: the rig to well under
  // a millimetre and a tenth of a degree.
  EXPECT_LT((result.cam2_from_cam1.translation - truth.translation).norm(), 1e-3);
  EXPECT_LT(AngleDeg(result.cam2_from_cam1.rotation, truth.rotation), 0.1);
  EXPECT_LT(result.overall_rms_px, 0.3);
}

TEST(StereoCalibration, RigBehindTwoDomes) {
  testing::TempDir dir;
  std::ofstream(dir / "rig.yaml") << R"(name: rig
seed: 8
num_images: 10
camera: {model: SIMPLE_RADIAL, width: 800, height: 600, params: [650.0, 400.0, 300.0, -0.03]}
housing: {model: DOMEPORT, params: [0.003, -0.002, 0.004, 0.05, 0.006, 1.0, 1.473, 1.334]}
stereo:
  cam2_from_cam1: {rotation_axis_angle_deg: [0.0, 1.0, 0.0, -4.0], translation: [-0.12, 0.0, 0.004]}
  housing2: {model: DOMEPORT, params: [-0.002, 0.001, 0.005, 0.05, 0.006, 1.0, 1.473, 1.334]}
target: {type: chessboard, cols: 8, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.5, 1.0], tilt_max_deg: 35, roll_max_deg: 20}
)";
  SynthesizeOptions synthesize;
  synthesize.config_path = (dir / "rig.yaml").string();
  synthesize.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(synthesize, progress);
  const GroundTruth truth = ReadGroundTruth(dir / "set/ground_truth.yaml");
  Extract(dir / "set/images", dir / "db.db", "SIMPLE_RADIAL", 8, 6, 0.025);
  for (int k = 0; k < 2; ++k) {  // each camera's housing calibration, known here
    CalibrationReport report;
    report.camera = k == 0 ? truth.camera : truth.stereo->camera2;
    report.housing = k == 0 ? truth.housing : truth.stereo->housing2;
    WriteCalibrationReport(report, dir / ("cam" + std::to_string(k + 1)));
  }
  StereoCalibratorOptions options;
  options.database_path = (dir / "db.db").string();
  options.output_path = (dir / "out").string();
  options.input_calibration1 = (dir / "cam1/calibration.yaml").string();
  options.input_calibration2 = (dir / "cam2/calibration.yaml").string();
  const StereoCalibrationResult result = RunStereoCalibrator(options, NoProgress());
  const Rigid3d& t = truth.stereo->cam2_from_cam1;
  EXPECT_LT((result.cam2_from_cam1.translation - t.translation).norm(), 1e-4);
  EXPECT_LT(AngleDeg(result.cam2_from_cam1.rotation, t.rotation), 0.005);
  EXPECT_LT(result.overall_rms_px, 0.05);
}

}  // namespace
}  // namespace portcal
