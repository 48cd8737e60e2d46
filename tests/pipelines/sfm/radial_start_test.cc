// The first radial term from two-view matches: synthetic views of a point
// cloud through a distorted lens (and a flat port), keypoints with pixel
// noise; the estimate, started from k1 = 0, must land near the lens's k1.
#include "pipelines/sfm/radial_start.h"

#include <gtest/gtest.h>

#include "tests/pipelines/sfm/matched_views.h"

namespace portcal {
namespace {

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
  const testing::MatchedViews scene = testing::MakeMatchedViews(truth, 6, 0.3, 3);
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
  const testing::MatchedViews scene = testing::MakeMatchedViews(truth, 5, 0.3, 5);
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
  const testing::MatchedViews scene = testing::MakeMatchedViews(pinhole, 3, 0.3, 7);
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
