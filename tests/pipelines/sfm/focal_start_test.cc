// The focal length from two-view matches: synthetic views of a point cloud
// through lenses from wide (0.35 x the width) to long (1.8 x), in air, behind
// a flat port, and a fisheye; started from the image reader's guess
// (1.2 x the width), the estimate must land near the lens's focal length,
// and views that cannot tell it (straight ahead) must say so.
#include "pipelines/sfm/focal_start.h"

#include <gtest/gtest.h>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "tests/pipelines/sfm/matched_views.h"

namespace portcal {
namespace {

using testing::MakeMatchedViews;
using testing::MatchedViews;
using testing::ViewMotion;

// The camera as the mapper starts it: the focal length guessed.
HousedCamera Guessed(HousedCamera camera) {
  for (const int idx : CameraModelFocalLengthIdxs(camera.camera.model_id))
    camera.camera.params[idx] = 1.2 * camera.camera.width;
  return camera;
}

// An undistorted 1280 x 720 lens of focal length `focal` in air.
HousedCamera InAirLens(double focal) {
  HousedCamera camera;
  camera.camera = Camera::FromModelName("RADIAL", focal, 1280, 720);
  camera.camera.params = {focal, 640, 360, 0, 0};
  return camera;
}

TEST(FocalStart, FindsFocalLengthsFromWideToLongInAir) {
  // Noise of 0.5 px: within 1 % (0.5 % measured) up to 1.2 x the width; a
  // long lens sees little perspective, within 5 % (3.6 % measured).
  for (const double factor : {0.35, 0.6, 1.2, 1.8}) {
    HousedCamera truth;
    truth.camera = Camera::FromModelName("RADIAL", factor * 1280, 1280, 720);
    truth.camera.params = {factor * 1280, 650, 355, -0.05, 0.01};
    const MatchedViews views = MakeMatchedViews(truth, 8, 0.5, 11, ViewMotion::kGeneral);
    std::string why_not;
    const auto start =
        EstimateFocalFromPairs(views.inputs, 1, Guessed(truth), FocalStartOptions(), &why_not);
    ASSERT_TRUE(start) << factor << ": " << why_not;
    EXPECT_NEAR(start->focal / (factor * 1280), 1.0, factor > 1.5 ? 0.05 : 0.01) << factor;
    EXPECT_GE(start->contrast, FocalStartOptions().min_contrast);
    EXPECT_GE(start->num_pairs, 10);  // of the 28, those that share 16 points
  }
}

TEST(FocalStart, FindsAWideLensBehindAFlatPortFromAnUntiltedGuess) {
  HousedCamera truth;
  truth.camera = Camera::FromModelName("OPENCV", 905, 1920, 1080);
  truth.camera.params = {905, 902, 981, 527, -0.3, 0.09, 0.0012, 0.0009};
  truth.housing = Housing::FromName(
      "FLATPORT", {0.0436194, 0, 0.9990482, 0.03, 0.008, 1, 1.473, 1.334}, "test");
  const MatchedViews views = MakeMatchedViews(truth, 8, 0.5, 5, ViewMotion::kGeneral);
  // The distortion known, the principal point at the centre (21 px off),
  // the port untilted (2.5 deg off): rays through a flat port are not
  // central, which the fit of a central model leaves as a few % of bias
  // (3.6 % measured).
  HousedCamera start = Guessed(truth);
  start.camera.params = {2304, 2304, 960, 540, -0.3, 0.09, 0, 0};
  start.housing = Housing::FromName("FLATPORT", {0, 0, 1, 0.03, 0.008, 1, 1.473, 1.334}, "test");
  std::string why_not;
  const auto estimate =
      EstimateFocalFromPairs(views.inputs, 1, start, FocalStartOptions(), &why_not);
  ASSERT_TRUE(estimate) << why_not;
  EXPECT_NEAR(estimate->focal / 905, 1.0, 0.05);
  // The distortion unknown as well: a strong lens bends the rays no focal
  // length straightens. The estimate must not then be confidently wrong:
  // none (the cost is flat), or near the truth.
  start.camera.params = {2304, 2304, 960, 540, 0, 0, 0, 0};
  const auto unknown =
      EstimateFocalFromPairs(views.inputs, 1, start, FocalStartOptions(), &why_not);
  if (unknown) EXPECT_NEAR(unknown->focal / 905, 1.0, 0.15);
}

TEST(FocalStart, FindsAFisheyesFocalLength) {
  HousedCamera truth;
  truth.camera = Camera::FromModelName("OPENCV_FISHEYE", 380, 960, 540);
  truth.camera.params = {380, 379, 472, 276, 0.06, -0.02, 0.004, -0.001};
  const MatchedViews views = MakeMatchedViews(truth, 8, 0.5, 7, ViewMotion::kGeneral);
  std::string why_not;
  const auto estimate =
      EstimateFocalFromPairs(views.inputs, 1, Guessed(truth), FocalStartOptions(), &why_not);
  ASSERT_TRUE(estimate) << why_not;
  EXPECT_NEAR(estimate->focal / 380, 1.0, 0.02);  // 0.7 % measured
}

TEST(FocalStart, ViewsStraightAheadSayTheyCannotTell) {
  // Translation alone: E = [t]x in every pair at every focal length.
  const HousedCamera truth = InAirLens(700);
  const MatchedViews views = MakeMatchedViews(truth, 8, 0.5, 3, ViewMotion::kForward);
  std::string why_not;
  EXPECT_FALSE(
      EstimateFocalFromPairs(views.inputs, 1, Guessed(truth), FocalStartOptions(), &why_not));
  EXPECT_NE(why_not.find("do not tell"), std::string::npos) << why_not;
  // Too few pairs: said, not guessed.
  const MatchedViews two = MakeMatchedViews(truth, 2, 0.5, 3, ViewMotion::kGeneral);
  EXPECT_FALSE(
      EstimateFocalFromPairs(two.inputs, 1, Guessed(truth), FocalStartOptions(), &why_not));
  EXPECT_NE(why_not.find("1 non-planar pairs"), std::string::npos) << why_not;
}

TEST(FocalStart, OrbitsAroundATargetStillTellIt) {
  // Optical axes meeting at the cloud's centre from nearly the same
  // distance is the critical motion for two views; the views' small
  // differences in distance and axis still tell f (0.6 % measured).
  const HousedCamera truth = InAirLens(700);
  const MatchedViews views = MakeMatchedViews(truth, 8, 0.5, 3, ViewMotion::kOrbit);
  std::string why_not;
  const auto estimate =
      EstimateFocalFromPairs(views.inputs, 1, Guessed(truth), FocalStartOptions(), &why_not);
  ASSERT_TRUE(estimate) << why_not;
  EXPECT_NEAR(estimate->focal / 700, 1.0, 0.02);
}

TEST(FocalStart, OptionsNameTheirFlag) {
  FocalStartOptions options;
  options.min_focal_factor = 3;
  try {
    options.Check();
    ADD_FAILURE();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--Mapper.init_focal_min_factor"), std::string::npos);
  }
}

}  // namespace
}  // namespace portcal
