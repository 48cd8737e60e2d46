// The first radial term from two-view matches: synthetic views of a point
// cloud through a distorted lens (and a flat port), keypoints with pixel
// noise; the estimate, started from k1 = 0, must land near the lens's k1.
#include "pipelines/sfm/radial_start.h"

#include <gtest/gtest.h>

#include <random>

namespace portcal {
namespace {

struct Scene {
  SfmInputs inputs;
  HousedCamera truth;
};

// `num_images` views on an arc around a cloud of points 0.6-1.0 m away,
// every view matched with every other; keypoints with noise `sigma_px`.
Scene MakeScene(const HousedCamera& truth, int num_images, double sigma_px, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, sigma_px);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 1500; ++i)
    points.emplace_back(0.45 * u(rng), 0.3 * u(rng), 0.8 + 0.2 * u(rng));
  Scene scene;
  scene.truth = truth;
  scene.inputs.cameras[1] = truth;
  const Housing* housing = truth.housing ? &*truth.housing : nullptr;
  // Per image, per point: its keypoint index (or -1).
  std::vector<std::vector<int>> index(num_images, std::vector<int>(points.size(), -1));
  for (int v = 0; v < num_images; ++v) {
    const double angle = 0.35 * (v - 0.5 * (num_images - 1)) / num_images;
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2 * u(rng), 1, 0.1 * u(rng)).normalized())
            .toRotationMatrix();
    // Orbiting the cloud's centre, looking at it.
    const Eigen::Vector3d target(0, 0, 0.8);
    const Eigen::Vector3d centre =
        target - R.transpose() * target + Eigen::Vector3d(0, 0.03 * u(rng), 0);
    SfmImage image;
    image.image_id = static_cast<image_t>(v + 1);
    image.name = "v" + std::to_string(v);
    image.camera_id = 1;
    for (size_t p = 0; p < points.size(); ++p) {
      const auto pixel = ProjectPoint(truth.camera, housing, R * (points[p] - centre));
      if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > truth.camera.width ||
          pixel->y() > truth.camera.height) {
        continue;
      }
      index[v][p] = static_cast<int>(image.keypoints.size());
      image.keypoints.push_back(*pixel + Eigen::Vector2d(noise(rng), noise(rng)));
    }
    image.correspondences.resize(image.keypoints.size());
    scene.inputs.images[image.image_id] = std::move(image);
  }
  for (int a = 0; a < num_images; ++a) {
    for (int b = a + 1; b < num_images; ++b) {
      int count = 0;
      for (size_t p = 0; p < points.size(); ++p) {
        if (index[a][p] < 0 || index[b][p] < 0) continue;
        scene.inputs.images[a + 1].correspondences[index[a][p]].push_back(
            {static_cast<image_t>(b + 1), static_cast<point2D_t>(index[b][p])});
        scene.inputs.images[b + 1].correspondences[index[b][p]].push_back(
            {static_cast<image_t>(a + 1), static_cast<point2D_t>(index[a][p])});
        ++count;
      }
      scene.inputs.pair_inliers[ImagePairToPairId(a + 1, b + 1)] = count;
    }
  }
  return scene;
}

HousedCamera WithoutDistortion(HousedCamera camera) {
  for (size_t i = 4; i < camera.camera.params.size(); ++i) camera.camera.params[i] = 0;
  return camera;
}

TEST(RadialStart, FindsTheFirstRadialTermOfAWideLensBehindAFlatPort) {
  HousedCamera truth;
  truth.camera = Camera::FromModelName("OPENCV", 905, 1920, 1080);
  truth.camera.params = {905, 902, 981, 527, -0.3, 0, 0.0012, 0.0009};
  truth.housing = Housing::FromName(
      "FLATPORT", {0.0436194, 0, 0.9990482, 0.03, 0.008, 1, 1.473, 1.334}, "test");
  const Scene scene = MakeScene(truth, 6, 0.3, 3);
  // All but k1 known: the estimate is the lens's k1 to the grid's step
  // (0.025). The trimmed residual is not smooth in k at that scale (the
  // kept 80 % change with k), so the parabola through the best three nodes
  // does not always improve on the best: the same data gave k within 0.015
  // of -0.3 in gcc's build and the next node, -0.275, in clang's.
  HousedCamera k1_unknown = truth;
  k1_unknown.camera.params[4] = 0;
  const auto exact = EstimateFirstRadialTerm(scene.inputs, 1, k1_unknown, RadialStartOptions());
  ASSERT_TRUE(exact);
  EXPECT_NEAR(exact->k, -0.3, 0.025 + 1e-12);
  EXPECT_LT(exact->residual_px, 0.45);  // Sampson's distance at 0.3 px per coordinate
  // The start as the mapper has it: the markers' focal length (1 % off),
  // the principal point at the centre (23 px off), no distortion, the
  // untilted port. The principal point's error is not projective once the
  // lens distorts, so the estimate is biased toward 0; the mapper needs a
  // start in the right basin (the render of docs/dev/auto_calibration_notes.md:
  // k1 = -0.21 and -0.25 for -0.3 both converged to -0.300, 0 did not).
  HousedCamera start = WithoutDistortion(truth);
  start.camera.params = {895, 895, 960, 540, 0, 0, 0, 0};
  start.housing = Housing::FromName("FLATPORT", {0, 0, 1, 0.03, 0.008, 1, 1.473, 1.334}, "test");
  const auto estimate = EstimateFirstRadialTerm(scene.inputs, 1, start, RadialStartOptions());
  ASSERT_TRUE(estimate);
  EXPECT_NEAR(estimate->k, -0.3, 0.08);
  EXPECT_LT(estimate->residual_px, 0.5 * estimate->residual_at_start_px);
  EXPECT_EQ(estimate->num_pairs, RadialStartOptions().max_num_pairs);
}

TEST(RadialStart, KeepsAnUndistortedLensUndistorted) {
  HousedCamera truth;
  truth.camera = Camera::FromModelName("RADIAL", 1300, 1920, 1080);
  truth.camera.params = {1300, 960, 540, 0, 0};
  const Scene scene = MakeScene(truth, 5, 0.3, 5);
  const auto estimate = EstimateFirstRadialTerm(scene.inputs, 1, truth, RadialStartOptions());
  ASSERT_TRUE(estimate);
  // The grid step is 0.025; noise of 0.3 px over ~10 pairs moves k1 by
  // well under that.
  EXPECT_NEAR(estimate->k, 0.0, 0.01);
  // At the truth the residual is the noise's: Sampson's distance of a
  // match with 0.3 px per coordinate in each image is ~0.3 px.
  EXPECT_LT(estimate->residual_px, 0.45);
}

TEST(RadialStart, NoRadialTermNoEstimate) {
  HousedCamera pinhole;
  pinhole.camera = Camera::FromModelName("PINHOLE", 1000, 1280, 720);
  const Scene scene = MakeScene(pinhole, 3, 0.3, 7);
  EXPECT_EQ(FirstRadialParamIdx(pinhole.camera), -1);
  EXPECT_FALSE(EstimateFirstRadialTerm(scene.inputs, 1, pinhole, RadialStartOptions()));
  HousedCamera fisheye;
  fisheye.camera = Camera::FromModelName("OPENCV_FISHEYE", 500, 1280, 720);
  EXPECT_EQ(FirstRadialParamIdx(fisheye.camera), 4);
}

TEST(RadialStart, OptionsAreChecked) {
  RadialStartOptions options;
  options.min_k = 0.5;
  options.max_k = -0.5;
  EXPECT_THROW(options.Check(), std::exception);
}

}  // namespace
}  // namespace portcal
