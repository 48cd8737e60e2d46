// portcal synthesize: rendered sets whose ground truth is exact (corners
// found in the images sit at the ground-truth pixels; the ground truth's
// pixels are the forward projections of its 3-D points), deterministic
// output, every target kind, stereo, survey and the underwater effects.
#include "pipelines/stages/synthesize.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "pipelines/target/corner_refinement.h"
#include "tests/test_utils.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

// A 1280 x 720 camera (the shared sets' 1920 x 1080 scaled by 2/3).
constexpr const char* kCamera = R"(camera:
  model: RADIAL
  width: 1280
  height: 720
  params: [864.91, 640.0, 360.0, -0.05, 0.01]
)";

constexpr const char* kChessboard = R"(target:
  type: chessboard
  cols: 10
  rows: 7
  square_size: 0.02
  margin: 0.015
poses:
  distance: [0.35, 0.8]
  tilt_max_deg: 40
  roll_max_deg: 30
  border_margin_px: 10
)";

fs::path WriteConfig(const testing::TempDir& dir, const std::string& name, const std::string& body,
                     int num_images) {
  const fs::path path = dir / (name + ".yaml");
  std::ofstream(path) << "name: " << name << "\nseed: 7\nnum_images: " << num_images << "\n"
                      << body;
  return path;
}

GroundTruth Synthesize(const fs::path& config, const fs::path& output, int64_t seed = -1) {
  SynthesizeOptions options;
  options.config_path = config.string();
  options.output_path = output.string();
  options.seed = seed;
  NullProgress progress;
  portcal::RunSynthesize(options, progress);
  return ReadGroundTruth(output / "ground_truth.yaml");
}

// Errors (px) of corners found by OpenCV and refined by portcal against the
// ground truth.
std::vector<double> CornerErrors(const fs::path& dir, const GroundTruth& truth) {
  const int cols = truth.target.inner_corners_cols, rows = truth.target.inner_corners_rows;
  std::vector<double> errors;
  for (const FrameTruth& frame : truth.images) {
    const cv::Mat image = cv::imread((dir / frame.cam1.file).string(), cv::IMREAD_GRAYSCALE);
    std::vector<cv::Point2f> found;
    EXPECT_TRUE(cv::findChessboardCorners(image, cv::Size(cols, rows), found)) << frame.cam1.file;
    if (found.size() != static_cast<size_t>(cols * rows)) continue;
    std::vector<Eigen::Vector2d> start;
    for (const cv::Point2f& p : found) start.emplace_back(p.x + 0.5, p.y + 0.5);
    // The board is symmetric under 180 degrees: take OpenCV's order that
    // starts at corner 0.
    if ((start.front() - *frame.cam1.corners_px.front()).norm() >
        (start.back() - *frame.cam1.corners_px.front()).norm()) {
      std::reverse(start.begin(), start.end());
    }
    const auto refined = RefineChessboardCorners(image, start, cols, rows);
    for (size_t i = 0; i < refined.size(); ++i) {
      EXPECT_TRUE(refined[i].has_value()) << frame.cam1.file << " corner " << i;
      if (refined[i]) errors.push_back((refined[i]->xy - *frame.cam1.corners_px[i]).norm());
    }
  }
  std::sort(errors.begin(), errors.end());
  return errors;
}

class SynthesizeHousings : public ::testing::TestWithParam<std::string> {};

TEST_P(SynthesizeHousings, CornersFoundInTheImagesSitAtTheGroundTruthPixels) {
  testing::TempDir dir;
  const std::string housing = GetParam() == "air" ? "housing: null\n"
                              : GetParam() == "flat"
                                  ? "housing:\n  model: FLATPORT\n  params: [0.08715574, 0.0, "
                                    "0.9961947, 0.02, 0.014, 1.0, 1.473, 1.334]\n"
                                  : "housing:\n  model: DOMEPORT\n  params: [0.01, 0.006, 0.002, "
                                    "0.05, 0.006, 1.0, 1.473, 1.334]\n";
  const fs::path config =
      WriteConfig(dir, GetParam(), std::string(kCamera) + housing + kChessboard, 6);
  const GroundTruth truth = Synthesize(config, dir / "set");
  ASSERT_EQ(truth.images.size(), 6u);
  const std::vector<double> errors = CornerErrors(dir / "set", truth);
  ASSERT_EQ(errors.size(), 6u * 70u);
  EXPECT_LT(errors[errors.size() / 2], 0.05) << GetParam();
  EXPECT_LT(errors.back(), 0.2) << GetParam();
  // The ground truth's pixels are the forward projections of its points.
  for (const FrameTruth& frame : truth.images) {
    for (size_t i = 0; i < truth.target.corners_3d.size(); ++i) {
      const auto pixel = ProjectPoint(truth.camera, truth.housing ? &*truth.housing : nullptr,
                                      frame.cam1.cam_from_target * truth.target.corners_3d[i]);
      ASSERT_TRUE(pixel && frame.cam1.corners_px[i]);
      EXPECT_LT((*pixel - *frame.cam1.corners_px[i]).norm(), 1e-9);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Housings, SynthesizeHousings, ::testing::Values("air", "flat", "dome"));

TEST(Synthesize, SameSeedSameBytesOtherSeedOtherImages) {
  testing::TempDir dir;
  const std::string small = R"(camera:
  model: SIMPLE_RADIAL
  width: 320
  height: 240
  params: [300.0, 160.0, 120.0, -0.02]
housing: null
)";
  const fs::path config = WriteConfig(dir, "small", small + std::string(kChessboard), 3);
  Synthesize(config, dir / "a");
  Synthesize(config, dir / "b");
  Synthesize(config, dir / "c", 99);
  for (const char* file : {"ground_truth.yaml", "images/img_001.png", "images/img_003.png"}) {
    EXPECT_EQ(testing::ReadFileToString(dir / "a" / file),
              testing::ReadFileToString(dir / "b" / file))
        << file;
  }
  EXPECT_NE(testing::ReadFileToString(dir / "a/images/img_001.png"),
            testing::ReadFileToString(dir / "c/images/img_001.png"));
  EXPECT_FALSE(fs::exists(dir / "a/.synthesize_staging"));
}

// A render that fails part way (a rig whose cameras look apart never sees
// the target with both) leaves no staging folder, no output folder that
// was not there, and an existing one as it was.
TEST(Synthesize, AFailedRunLeavesTheOutputAsItWas) {
  testing::TempDir dir;
  const std::string apart = R"(housing: null
stereo:
  cam2_from_cam1:
    rotation_axis_angle_deg: [0.0, 1.0, 0.0, 180.0]
    translation: [-0.1, 0.0, 0.0]
)";
  const fs::path config = WriteConfig(dir, "apart", std::string(kCamera) + apart + kChessboard, 3);
  EXPECT_THROW(Synthesize(config, dir / "new"), NumericalError);
  EXPECT_FALSE(fs::exists(dir / "new"));
  fs::create_directories(dir / "old");
  std::ofstream(dir / "old/notes.txt") << "mine";
  EXPECT_THROW(Synthesize(config, dir / "old"), NumericalError);
  EXPECT_EQ(testing::ReadFileToString(dir / "old/notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(dir / "old/.synthesize_staging"));
}

TEST(Synthesize, StereoGroundTruthComposesTheRig) {
  testing::TempDir dir;
  const std::string stereo = R"(housing: null
stereo:
  cam2_from_cam1:
    rotation_axis_angle_deg: [0.0, 1.0, 0.0, 3.0]
    translation: [-0.1, 0.0, 0.005]
)";
  const fs::path config =
      WriteConfig(dir, "stereo", std::string(kCamera) + stereo + kChessboard, 3);
  const GroundTruth truth = Synthesize(config, dir / "set");
  ASSERT_TRUE(truth.stereo.has_value());
  for (const FrameTruth& frame : truth.images) {
    ASSERT_TRUE(frame.cam2.has_value());
    EXPECT_TRUE(fs::exists(dir / "set" / frame.cam2->file));
    const Rigid3d composed = truth.stereo->cam2_from_cam1 * frame.cam1.cam_from_target;
    EXPECT_LT((composed.translation - frame.cam2->cam_from_target.translation).norm(), 1e-12);
    for (const auto& corner : frame.cam2->corners_px) {
      ASSERT_TRUE(corner.has_value());
      EXPECT_TRUE(corner->x() > 0 && corner->x() < 1280 && corner->y() > 0 && corner->y() < 720);
    }
  }
}

// ArUco boards, ChArUco and the 3-D target: OpenCV's detector finds the
// markers the ground truth lists, where it lists them.
void ExpectMarkersDetected(const fs::path& dir, const GroundTruth& truth) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  // OpenCV fits lines to the marker contour (no corner refinement, which can
  // jump to a neighbouring marker): accurate to a fraction of a pixel.
  parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
  int num_matched = 0;
  for (const FrameTruth& frame : truth.images) {
    const cv::Mat image = cv::imread((dir / frame.cam1.file).string(), cv::IMREAD_GRAYSCALE);
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(image, dictionary, corners, ids, parameters);
    for (const ImageTruth::Marker& marker : frame.cam1.markers) {
      if (!marker.fully_inside) continue;
      const auto it = std::find(ids.begin(), ids.end(), marker.id);
      ASSERT_NE(it, ids.end()) << frame.cam1.file << " marker " << marker.id;
      const auto& found = corners[it - ids.begin()];
      // Contour corners carry OpenCV's own bias of up to ~1 px (they sit on
      // boundary pixels of the thresholded image), mostly symmetric about the
      // marker, so the centre moves less (0.3-0.4 px seen); each corner is in
      // its place of the order (a wrong layout or orientation would be off by
      // whole modules, 5+ px).
      Eigen::Vector2d found_centre = Eigen::Vector2d::Zero(),
                      truth_centre = Eigen::Vector2d::Zero();
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector2d xy(found[k].x + 0.5, found[k].y + 0.5);
        EXPECT_LT((xy - marker.corners_px[k]).norm(), 1.5)
            << frame.cam1.file << " marker " << marker.id << " corner " << k;
        found_centre += xy / 4;
        truth_centre += marker.corners_px[k] / 4;
      }
      EXPECT_LT((found_centre - truth_centre).norm(), 0.6)
          << frame.cam1.file << " marker " << marker.id;
      ++num_matched;
    }
  }
  EXPECT_GT(num_matched, 0);
}

TEST(Synthesize, MarkerTargetsAreDetectedWhereTheGroundTruthSays) {
  testing::TempDir dir;
  const std::map<std::string, std::string> targets = {{"aruco_grid", R"(target:
  type: aruco_grid
  markers_x: 4
  markers_y: 3
  marker_size: 0.04
  marker_separation: 0.01
  dictionary: DICT_4X4_50
poses:
  distance: [0.35, 0.7]
  tilt_max_deg: 35
)"},
                                                      {"charuco", R"(target:
  type: charuco
  squares_x: 6
  squares_y: 5
  square_size: 0.03
  marker_size: 0.022
  dictionary: DICT_4X4_50
poses:
  distance: [0.4, 0.8]
  tilt_max_deg: 35
)"},
                                                      {"target3d", R"(target:
  type: target3d
  num_faces: 2
  fold_angle_deg: 120
  face_width: 0.2
  face_height: 0.25
  aruco_dict: DICT_4X4_50
  marker_ids: [0, 1]
  marker_size: 0.06
clutter:
  enabled: true
  distance: 3.0
poses:
  distance: [0.5, 1.0]
  tilt_max_deg: 30
)"}};
  for (const auto& [name, target] : targets) {
    const fs::path config =
        WriteConfig(dir, name, std::string(kCamera) + "housing: null\n" + target, 3);
    const GroundTruth truth = Synthesize(config, dir / name);
    EXPECT_EQ(truth.target.type, name);
    ExpectMarkersDetected(dir / name, truth);
    if (name == "target3d") {
      EXPECT_TRUE(fs::exists(dir / name / "target_dots.csv"));
      EXPECT_EQ(truth.target.faces.size(), 2u);
      EXPECT_GT(truth.target.faces[0].num_dots, 100);
    }
    if (name == "charuco") {
      EXPECT_EQ(truth.target.corners_3d.size(), 20u);
    }
  }
}

TEST(Synthesize, UnderwaterEffectsChangeTheImageAsPhysicsSays) {
  testing::TempDir dir;
  const std::string base =
      std::string(kCamera) + "housing: null\n" + kChessboard + "render:\n  noise_sigma: 0.0\n";
  const auto render = [&](const std::string& name, const std::string& extra) {
    Synthesize(WriteConfig(dir, name, base + extra, 1), dir / name);
    return cv::imread((dir / name / "images/img_001.png").string(), cv::IMREAD_GRAYSCALE);
  };
  const cv::Mat clean = render("clean", "");
  const cv::Mat murky = render("murky", "water:\n  attenuation: 0.8\n  backscatter: 140\n");
  const cv::Mat vignetted = render("vignetted", "vignetting: 0.8\n");
  const cv::Mat blurred =
      render("motion", "motion_blur:\n  velocity: [0.5, 0.0, 0.0]\n  exposure: 0.01\n");
  double clean_min, clean_max, murky_min, murky_max;
  cv::minMaxLoc(clean, &clean_min, &clean_max);
  cv::minMaxLoc(murky, &murky_min, &murky_max);
  // Attenuation and backscatter: less contrast, the veil where no target is.
  EXPECT_LT(murky_max - murky_min, 0.8 * (clean_max - clean_min));
  EXPECT_EQ(murky.at<uint8_t>(0, 0), 140);
  // Vignetting darkens the corners, not the centre.
  EXPECT_LT(vignetted.at<uint8_t>(0, 0), clean.at<uint8_t>(0, 0) - 20);
  EXPECT_NEAR(vignetted.at<uint8_t>(360, 640), clean.at<uint8_t>(360, 640), 3);
  // Motion blur spreads the edges: less high-frequency energy.
  cv::Mat lap_clean, lap_motion;
  cv::Laplacian(clean, lap_clean, CV_64F);
  cv::Laplacian(blurred, lap_motion, CV_64F);
  EXPECT_LT(cv::norm(lap_motion), 0.8 * cv::norm(lap_clean));
}

TEST(Synthesize, OccludersHideCornersAndTheGroundTruthSaysWhich) {
  testing::TempDir dir;
  const fs::path config = WriteConfig(dir, "occluded",
                                      std::string(kCamera) + "housing: null\n" + kChessboard +
                                          "occlusion:\n  probability: 1.0\n  fraction: 0.3\n",
                                      4);
  const GroundTruth truth = Synthesize(config, dir / "set");
  int hidden = 0;
  for (const FrameTruth& frame : truth.images) {
    for (bool visible : frame.cam1.corners_visible) hidden += !visible;
  }
  EXPECT_GT(hidden, 0);
}

TEST(Synthesize, SurveyFollowsTheLawnmowerPath) {
  testing::TempDir dir;
  const std::string survey = R"(camera:
  model: PINHOLE
  width: 400
  height: 300
  params: [300.0, 300.0, 200.0, 150.0]
housing:
  model: FLATPORT
  params: [0.0, 0.0, 1.0, 0.02, 0.01, 1.0, 1.49, 1.334]
survey:
  height: 2.0
  speed: 0.5
  frame_rate: 1.0
  side_overlap: 0.6
  line_length: 2.0
  roughness: 0.1
render:
  spp: 2
)";
  const GroundTruth truth = Synthesize(WriteConfig(dir, "survey", survey, 8), dir / "set");
  ASSERT_EQ(truth.images.size(), 8u);
  EXPECT_EQ(truth.target.type, "seabed");
  // 5 frames per 2 m line at 0.5 m per frame, then the next line back.
  const Eigen::Vector3d first = truth.images[0].cam1.cam_from_target.Inverse().translation;
  const Eigen::Vector3d fifth = truth.images[4].cam1.cam_from_target.Inverse().translation;
  const Eigen::Vector3d sixth = truth.images[5].cam1.cam_from_target.Inverse().translation;
  EXPECT_NEAR((fifth - first).norm(), 2.0, 1e-9);
  EXPECT_NEAR(sixth.x(), fifth.x(), 1e-9);
  EXPECT_GT(sixth.y() - fifth.y(), 0.1);
  EXPECT_NEAR(first.z(), 2.0, 1e-12);
  // A textured seabed, not an empty frame.
  const cv::Mat image =
      cv::imread((dir / "set" / truth.images[0].cam1.file).string(), cv::IMREAD_GRAYSCALE);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_GT(stddev[0], 20);
}

TEST(Synthesize, BadConfigsNameTheFileAndKey) {
  testing::TempDir dir;
  const auto message = [&](const std::string& body) {
    try {
      Synthesize(WriteConfig(dir, "bad", body, 2), dir / "out");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(std::string(kCamera) + "target:\n  type: hexagon\n").find("target.type"),
            std::string::npos);
  EXPECT_NE(
      message(std::string(kCamera) +
              "housing:\n  model: DOMEPORT\n  params: [0.1, 0, 0, 0.05, 0.006, 1, 1.5, 1.33]\n" +
              kChessboard)
          .find("inside"),
      std::string::npos);
  EXPECT_NE(message("camera:\n  model: RADIAL\n  width: 100\n  height: 100\n  params: [1, 2]\n")
                .find("bad.yaml"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out" / "ground_truth.yaml"));
}

TEST(GroundTruthFile, ReadsEverySharedSetAndRoundTrips) {
  PORTCAL_REQUIRE_SHARED(shared);
  int num_read = 0;
  for (const auto& entry : fs::directory_iterator(shared / "datasets/rendered")) {
    const fs::path path = entry.path() / "ground_truth.yaml";
    if (!fs::exists(path)) continue;
    const GroundTruth truth = ReadGroundTruth(path);
    EXPECT_EQ(truth.images.size(), 25u) << path;
    EXPECT_FALSE(truth.target.type.empty());
    testing::TempDir dir;
    WriteGroundTruth(truth, dir / "gt.yaml");
    const GroundTruth again = ReadGroundTruth(dir / "gt.yaml");
    ASSERT_EQ(again.images.size(), truth.images.size());
    EXPECT_EQ(again.camera.params, truth.camera.params);
    EXPECT_EQ(again.target.markers.size(), truth.target.markers.size());
    for (size_t i = 0; i < truth.images.size(); ++i) {
      EXPECT_EQ(again.images[i].cam1.cam_from_target.translation,
                truth.images[i].cam1.cam_from_target.translation);
      ASSERT_EQ(again.images[i].cam1.corners_px.size(), truth.images[i].cam1.corners_px.size());
      for (size_t k = 0; k < truth.images[i].cam1.corners_px.size(); ++k) {
        EXPECT_EQ(*again.images[i].cam1.corners_px[k], *truth.images[i].cam1.corners_px[k]);
      }
    }
    ++num_read;
  }
  EXPECT_GE(num_read, 6);
}

}  // namespace
}  // namespace portcal
