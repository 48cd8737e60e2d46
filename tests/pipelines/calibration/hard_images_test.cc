// Calibration where images are hard, as underwater images are: low contrast
// and backscatter, forward scatter, blur, strong noise, vignetting, partly
// occluded boards, plus views of another target and of nothing. The
// detector must refuse what is wrong and say why, and the calibration stay
// within its standard deviations of the truth.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "database/database.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/target_views.h"
#include "pipelines/stages/synthesize.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

TEST(HardImages, DetectorRefusesWhatIsWrongAndCalibrationHolds) {
  testing::TempDir dir;
  const std::string camera =
      "camera: {model: RADIAL, width: 800, height: 600, params: [650.0, 402.0, 298.0, -0.08, "
      "0.01]}\n"
      "housing: null\n";
  std::ofstream(dir / "hard.yaml") << "name: hard\nseed: 31\nnum_images: 14\n"
                                   << camera << R"(
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.025, margin: 0.015}
poses: {distance: [0.35, 0.9], tilt_max_deg: 45, roll_max_deg: 40}
render: {spp: 4, blur_sigma: 0.8, noise_sigma: 3.0, white: 200, black: 60}
water: {attenuation: 0.5, backscatter: 120, forward_scatter: 0.4}
vignetting: 0.5
occlusion: {probability: 0.25, fraction: 0.2}
)";
  // Another target (a ChArUco board) in the same folder.
  std::ofstream(dir / "other.yaml") << "name: other\nseed: 32\nnum_images: 2\n"
                                    << camera << R"(
target: {type: charuco, squares_x: 6, squares_y: 5, square_size: 0.03, marker_size: 0.022}
poses: {distance: [0.4, 0.8], tilt_max_deg: 30}
)";
  NullProgress progress;
  for (const char* name : {"hard", "other"}) {
    SynthesizeOptions options;
    options.config_path = (dir / (std::string(name) + ".yaml")).string();
    options.output_path = (dir / name).string();
    RunSynthesize(options, progress);
  }
  const GroundTruth truth = ReadGroundTruth(dir / "hard/ground_truth.yaml");
  fs::create_directories(dir / "images");
  for (const auto& entry : fs::directory_iterator(dir / "hard/images")) {
    fs::copy(entry.path(), dir / "images" / entry.path().filename());
  }
  fs::copy(dir / "other/images/img_001.png", dir / "images/zz_other_target_1.png");
  fs::copy(dir / "other/images/img_002.png", dir / "images/zz_other_target_2.png");
  cv::Mat nothing(600, 800, CV_8UC1);
  cv::randu(nothing, 80, 140);
  cv::imwrite((dir / "images/zz_nothing.png").string(), nothing);

  TargetExtractorOptions extract;
  extract.database_path = (dir / "db.db").string();
  extract.image_path = (dir / "images").string();
  extract.reader.camera_model = "RADIAL";
  extract.reader.single_camera = true;
  extract.chessboard.cols = 9;
  extract.chessboard.rows = 6;
  extract.square_size_m = 0.025;
  const TargetExtractorSummary summary = RunTargetExtractor(extract, progress);
  EXPECT_EQ(summary.num_images, 17);
  Database db(dir / "db.db", Database::OpenMode::kReadOnly);
  for (const char* name : {"zz_other_target_1.png", "zz_other_target_2.png", "zz_nothing.png"}) {
    const auto status = db.ReadTargetDetectionStatus(db.ReadImageWithName(name)->image_id);
    ASSERT_TRUE(status.has_value()) << name;
    EXPECT_FALSE(status->found) << name;
    EXPECT_FALSE(status->reason.empty()) << name;
  }
  // Clean views must not be lost: every view the occluder spared is found.
  int spared = 0, found_spared = 0;
  for (const FrameTruth& frame : truth.images) {
    if (!frame.cam1.corners_visible.empty()) continue;  // partly occluded
    ++spared;
    const auto status = db.ReadTargetDetectionStatus(
        db.ReadImageWithName(fs::path(frame.cam1.file).filename().string())->image_id);
    found_spared += status && status->found;
  }
  EXPECT_EQ(found_spared, spared);

  CameraCalibrationSettings settings;
  settings.drop_outlier_views = true;
  const CameraCalibrationResult result =
      CalibrateCamera(ReadTargetViews(&db).by_camera.begin()->second,
                      Camera::FromModelName("RADIAL", 700, 800, 600), settings);
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT(std::abs(result.camera.params[i] - truth.camera.params[i]),
              4 * result.params_std_dev[i])
        << "parameter " << i << " " << result.camera.params[i] << " +- "
        << result.params_std_dev[i];
  }
  for (const CalibratedView& view : result.views) EXPECT_FALSE(view.dropped) << view.image_name;
}

}  // namespace
}  // namespace portcal
