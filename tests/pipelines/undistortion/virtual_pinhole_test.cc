// The virtual pinhole and its error: exact in air (lens distortion only),
// tiny behind a centred dome, zero at the design depth behind a flat port
// and growing away from it; the field of view as blank_pixels asks; the
// design depth that balances a range's ends.
#include "pipelines/undistortion/virtual_pinhole.h"

#include <gtest/gtest.h>

#include <random>

#include "pipelines/undistortion/approximation_error.h"

namespace portcal {
namespace {

Camera DistortedCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 700, 960, 600);
  // An off-centre principal point and tangential distortion, as real lenses have.
  camera.params = {700, 705, 492.5, 288.0, -0.28, 0.09, 0.0012, -0.0008};
  return camera;
}

Housing FlatPort() {
  const double tilt = 4.0 * M_PI / 180.0;
  return Housing::FromName(
      "FLATPORT", {std::sin(tilt), 0, std::cos(tilt), 0.025, 0.012, 1.0, 1.49, 1.334}, "test");
}

Housing DomePort(const Eigen::Vector3d& centre) {
  return Housing::FromName(
      "DOMEPORT", {centre.x(), centre.y(), centre.z(), 0.06, 0.008, 1.0, 1.49, 1.334}, "test");
}

Camera InAirPinholeLens() {
  Camera camera = Camera::FromModelName("RADIAL", 800, 960, 600);
  camera.params = {800, 486.0, 296.5, -0.05, 0.01};
  return camera;
}

TEST(VirtualPinhole, InAirIsExactAtEveryDepth) {
  const VirtualPinhole pinhole =
      FitVirtualPinhole({DistortedCamera(), std::nullopt}, 1.0, Eigen::Matrix3d::Identity(), {});
  const ApproximationError error = MeasureApproximationError(pinhole, {0.2, 1.0, 50.0}, 32, 1);
  EXPECT_LT(error.worst_px, 1e-6);
  // A source pixel and its output pixel map onto each other.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(5, 955), y(5, 595);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d source(x(rng), y(rng));
    const std::optional<Eigen::Vector2d> output = pinhole.OutputPixel(source);
    ASSERT_TRUE(output);
    const std::optional<Eigen::Vector2d> back = pinhole.SourcePixel(*output);
    ASSERT_TRUE(back);
    EXPECT_LT((*back - source).norm(), 1e-7);
  }
}

// Output pixels near the border, mapped back into the camera's image.
int CountOutside(const VirtualPinhole& pinhole) {
  int outside = 0;
  const double w = static_cast<double>(pinhole.pinhole.width),
               h = static_cast<double>(pinhole.pinhole.height);
  for (double t = 0; t <= 1.0; t += 1.0 / 64) {
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(0.5, 0.5 + t * (h - 1)), Eigen::Vector2d(w - 0.5, 0.5 + t * (h - 1)),
          Eigen::Vector2d(0.5 + t * (w - 1), 0.5), Eigen::Vector2d(0.5 + t * (w - 1), h - 0.5)}) {
      const std::optional<Eigen::Vector2d> source = pinhole.SourcePixel(pixel);
      const bool inside = source && source->x() >= 0 && source->y() >= 0 &&
                          source->x() <= static_cast<double>(pinhole.source.camera.width) &&
                          source->y() <= static_cast<double>(pinhole.source.camera.height);
      outside += inside ? 0 : 1;
    }
  }
  return outside;
}

TEST(VirtualPinhole, BlankPixelsChoosesTheFieldOfView) {
  const HousedCamera camera{DistortedCamera(), std::nullopt};
  FieldOfViewOptions none, all;
  all.blank_pixels = 1.0;
  const VirtualPinhole tight = FitVirtualPinhole(camera, 1.0, Eigen::Matrix3d::Identity(), none);
  const VirtualPinhole wide = FitVirtualPinhole(camera, 1.0, Eigen::Matrix3d::Identity(), all);
  // Barrel distortion: without blank pixels the output is smaller.
  EXPECT_LT(tight.pinhole.width, wide.pinhole.width);
  EXPECT_LT(tight.pinhole.height, wide.pinhole.height);
  EXPECT_EQ(CountOutside(tight), 0);
  EXPECT_GT(CountOutside(wide), 0);
  // Every pixel of the camera's border lands inside the wide output.
  for (double t = 0; t <= 1.0; t += 1.0 / 64) {
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(0, t * 600), Eigen::Vector2d(960, t * 600), Eigen::Vector2d(t * 960, 0),
          Eigen::Vector2d(t * 960, 600)}) {
      const Eigen::Vector2d output = *wide.OutputPixel(pixel);
      EXPECT_GE(output.x(), -1.0);
      EXPECT_GE(output.y(), -1.0);
      EXPECT_LE(output.x(), static_cast<double>(wide.pinhole.width) + 1.0);
      EXPECT_LE(output.y(), static_cast<double>(wide.pinhole.height) + 1.0);
    }
  }
  FieldOfViewOptions small;
  small.max_image_size = 400;
  const VirtualPinhole shrunk = FitVirtualPinhole(camera, 1.0, Eigen::Matrix3d::Identity(), small);
  EXPECT_EQ(std::max(shrunk.pinhole.width, shrunk.pinhole.height), 400u);
  EXPECT_NEAR(shrunk.pinhole.params[0] / tight.pinhole.params[0],
              400.0 / static_cast<double>(std::max(tight.pinhole.width, tight.pinhole.height)),
              1e-3);
}

TEST(VirtualPinhole, CentredDomeIsNearlyExactEverywhere) {
  const HousedCamera centred{InAirPinholeLens(), DomePort(Eigen::Vector3d::Zero())};
  const VirtualPinhole pinhole = FitVirtualPinhole(centred, 2.0, Eigen::Matrix3d::Identity(), {});
  // The dome does not magnify: the pinhole keeps the lens's focal length.
  EXPECT_NEAR(pinhole.pinhole.params[0], 800.0, 1.0);
  const ApproximationError error =
      MeasureApproximationError(pinhole, SampleDepths({0.3, 20.0}, 5, 2.0), 32, 2);
  EXPECT_LT(error.worst_px, 1e-3);
  // 3 mm off-centre: the rays miss the camera centre, and the error shows.
  const HousedCamera decentred{InAirPinholeLens(), DomePort(Eigen::Vector3d(0.003, 0, 0))};
  const VirtualPinhole off = FitVirtualPinhole(decentred, 2.0, Eigen::Matrix3d::Identity(), {});
  const ApproximationError off_error =
      MeasureApproximationError(off, SampleDepths({0.3, 20.0}, 5, 2.0), 32, 2);
  EXPECT_GT(off_error.worst_px, 0.3);
}

TEST(VirtualPinhole, FlatPortErrorGrowsAwayFromTheDesignDepth) {
  const HousedCamera camera{InAirPinholeLens(), FlatPort()};
  const VirtualPinhole pinhole = FitVirtualPinhole(camera, 1.0, Eigen::Matrix3d::Identity(), {});
  // Behind water the camera sees narrower: the apparent focal length is
  // about n_water times the lens's.
  EXPECT_NEAR(pinhole.pinhole.params[0] / 800.0, 1.334, 0.02);
  const ApproximationError error =
      MeasureApproximationError(pinhole, {0.3, 0.5, 1.0, 2.0, 8.0}, 32, 2);
  ASSERT_EQ(error.depths.size(), 5u);
  EXPECT_LT(error.depths[2].max_px, 1e-6);
  EXPECT_GT(error.depths[1].max_px, 0.5);
  EXPECT_GT(error.depths[0].max_px, error.depths[1].max_px);
  EXPECT_GT(error.depths[4].max_px, error.depths[3].max_px);
  EXPECT_EQ(error.worst_depth, 0.3);
  // Where a pixel shows something, the error is a number; grey elsewhere.
  EXPECT_GE(error.depths[0].grid.minCoeff(), 0.0);
}

TEST(VirtualPinhole, ChosenDesignDepthBalancesTheRange) {
  const HousedCamera camera{InAirPinholeLens(), FlatPort()};
  const DepthRange range{0.5, 3.0};
  const double design = ChooseDesignDepth(camera, range, Eigen::Matrix3d::Identity(), {});
  ASSERT_GT(design, range.near);
  ASSERT_LT(design, range.far);
  const VirtualPinhole chosen = FitVirtualPinhole(camera, design, Eigen::Matrix3d::Identity(), {});
  const ApproximationError error =
      MeasureApproximationError(chosen, SampleDepths(range, 7, design), 32, 2);
  // The worst error sits at both ends alike (minimax), within 2 %.
  EXPECT_NEAR(error.depths.front().max_px, error.depths.back().max_px, 0.02 * error.worst_px);
  // Better than the ends' and the refractive fork's fixed 5 m.
  for (const double other : {0.5, 3.0, 5.0}) {
    const VirtualPinhole fixed = FitVirtualPinhole(camera, other, Eigen::Matrix3d::Identity(), {});
    EXPECT_LT(error.worst_px,
              MeasureApproximationError(fixed, SampleDepths(range, 7, other), 32, 2).worst_px)
        << other;
  }
}

TEST(VirtualPinhole, HousingReachIsThePortsOuterSurface) {
  EXPECT_EQ(HousingReach({InAirPinholeLens(), std::nullopt}), 0.0);
  const double reach = HousingReach({InAirPinholeLens(), FlatPort()});
  // 25 mm + 12 mm glass on the axis, a little more off it on a tilted port.
  EXPECT_GT(reach, 0.037);
  EXPECT_LT(reach, 0.045);
}

}  // namespace
}  // namespace portcal
