// Rectified pairs: in air a point's two images share a row and their
// disparity is f B / z exactly; behind flat ports the same holds at the
// design depth, and elsewhere the rows disagree by no more than the two
// cameras' reported errors.
#include "pipelines/undistortion/stereo_rectification.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

Camera Lens(double cx, double k1) {
  Camera camera = Camera::FromModelName("OPENCV", 640, 800, 600);
  camera.params = {640, 643, cx, 296.0, k1, 0.02, 0.0005, -0.0003};
  return camera;
}

// Camera 2 12 cm to the right, toed in by 2 deg and rolled by 1 deg.
Rigid3d ToedInRig() {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(-2.0 * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(1.0 * M_PI / 180, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d centre2(0.12, 0.004, 0.002);
  return Rigid3d(rotation, -(rotation * centre2));
}

TEST(StereoRectification, InAirRowsAgreeAndDisparityIsFocalTimesBaselineOverDepth) {
  const Rigid3d cam2_from_cam1 = ToedInRig();
  const RectifyingRotations rotations = RectifyingRotationsOf(cam2_from_cam1);
  EXPECT_NEAR(rotations.baseline, Eigen::Vector3d(0.12, 0.004, 0.002).norm(), 1e-12);
  const auto [first, second] =
      FitRectifiedPinholes({Lens(402.5, -0.2), std::nullopt}, {Lens(396.0, -0.18), std::nullopt},
                           rotations, 1.0, 1.0, {});
  EXPECT_EQ(first.pinhole.params[0], second.pinhole.params[0]);
  EXPECT_EQ(first.pinhole.params[3], second.pinhole.params[3]);
  EXPECT_EQ(first.pinhole.height, second.pinhole.height);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> x(-0.5, 0.6), y(-0.4, 0.4), z(0.6, 6.0);
  int checked = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d point1(x(rng), y(rng), z(rng));
    const std::optional<Eigen::Vector2d> pixel1 = first.source.Project(point1);
    const std::optional<Eigen::Vector2d> pixel2 = second.source.Project(cam2_from_cam1 * point1);
    if (!pixel1 || !pixel2) continue;
    const Eigen::Vector2d rectified1 = *first.OutputPixel(*pixel1),
                          rectified2 = *second.OutputPixel(*pixel2);
    EXPECT_NEAR(rectified1.y(), rectified2.y(), 1e-6);
    const double depth = (rotations.rect_from_cam1 * point1).z();
    const double disparity =
        rectified1.x() - rectified2.x() - (first.pinhole.params[2] - second.pinhole.params[2]);
    EXPECT_NEAR(disparity, first.pinhole.params[0] * rotations.baseline / depth, 1e-6);
    ++checked;
  }
  EXPECT_GT(checked, 400);
}

TEST(StereoRectification, BehindFlatPortsRowsAgreeWithinTheReportedErrors) {
  const Housing port =
      Housing::FromName("FLATPORT", {0, 0, 1, 0.02, 0.01, 1.0, 1.49, 1.334}, "test");
  const Rigid3d cam2_from_cam1(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.15, 0, 0));
  const RectifyingRotations rotations = RectifyingRotationsOf(cam2_from_cam1);
  const double design = 1.5;
  const auto [first, second] = FitRectifiedPinholes(
      {Lens(402.5, -0.2), port}, {Lens(396.0, -0.18), port}, rotations, design, design, {});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.15, 0.85);
  for (const double depth : {design, 0.8, 4.0}) {
    double largest_row_gap = 0;
    for (int i = 0; i < 300; ++i) {
      // A point at this depth seen by camera 1, also seen by camera 2.
      const Eigen::Vector2d pixel1(u(rng) * 800, u(rng) * 600);
      const Eigen::Vector3d point1 = *first.PointAtDepth(pixel1, depth);
      const std::optional<Eigen::Vector2d> pixel2 = second.source.Project(cam2_from_cam1 * point1);
      if (!pixel2 || pixel2->x() < 0 || pixel2->x() > 800) continue;
      const Eigen::Vector2d rectified1 = *first.OutputPixel(pixel1),
                            rectified2 = *second.OutputPixel(*pixel2);
      const double row_gap = std::abs(rectified1.y() - rectified2.y());
      const std::optional<double> error1 = first.ErrorAtDepth(rectified1, depth);
      const std::optional<double> error2 = second.ErrorAtDepth(rectified2, depth);
      ASSERT_TRUE(error1 && error2);
      EXPECT_LE(row_gap, *error1 + *error2 + 1e-6) << depth;
      if (depth == design) {
        EXPECT_LT(row_gap, 1e-6);
      }
      largest_row_gap = std::max(largest_row_gap, row_gap);
    }
    if (depth != design) {
      EXPECT_GT(largest_row_gap, 0.01) << depth;  // a flat port is no pinhole
    }
  }
}

// The rendered stereo set's corners (an independent ray tracer's pixels,
// 1e-6 px from portcal's projection): each corner's two rectified pixels
// share a row, and the disparity gives its depth.
TEST(StereoRectification, RenderedRigCornersShareRows) {
  PORTCAL_REQUIRE_SHARED(shared);
  const GroundTruth truth =
      ReadGroundTruth(shared / "datasets" / "rendered" / "chess_stereo_air" / "ground_truth.yaml");
  ASSERT_TRUE(truth.stereo);
  const RectifyingRotations rotations = RectifyingRotationsOf(truth.stereo->cam2_from_cam1);
  const auto [first, second] = FitRectifiedPinholes(
      {truth.camera, std::nullopt}, {truth.stereo->camera2, std::nullopt}, rotations, 1.0, 1.0, {});
  double largest_row_gap = 0, largest_depth_error = 0;
  int checked = 0;
  for (const FrameTruth& frame : truth.images) {
    ASSERT_TRUE(frame.cam2);
    for (size_t i = 0; i < truth.target.corners_3d.size(); ++i) {
      if (!frame.cam1.corners_px[i] || !frame.cam2->corners_px[i]) continue;
      const Eigen::Vector2d rectified1 = *first.OutputPixel(*frame.cam1.corners_px[i]);
      const Eigen::Vector2d rectified2 = *second.OutputPixel(*frame.cam2->corners_px[i]);
      largest_row_gap = std::max(largest_row_gap, std::abs(rectified1.y() - rectified2.y()));
      const double disparity =
          rectified1.x() - rectified2.x() - (first.pinhole.params[2] - second.pinhole.params[2]);
      const Eigen::Vector3d point = frame.cam1.cam_from_target * truth.target.corners_3d[i];
      const double depth = (rotations.rect_from_cam1 * point).z();
      largest_depth_error =
          std::max(largest_depth_error,
                   std::abs(first.pinhole.params[0] * rotations.baseline / disparity - depth));
      ++checked;
    }
  }
  std::printf(
      "%d corners: rows apart by at most %.2e px, depth from disparity off by at most %.2e m\n",
      checked, largest_row_gap, largest_depth_error);
  EXPECT_GT(checked, 500);
  EXPECT_LT(largest_row_gap, 1e-4);
  EXPECT_LT(largest_depth_error, 1e-6);
}

TEST(StereoRectification, BaselineAlongTheAxesHasNoRectification) {
  const Rigid3d forward(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -0.2));
  EXPECT_THROW(RectifyingRotationsOf(forward), InputError);
}

}  // namespace
}  // namespace portcal
