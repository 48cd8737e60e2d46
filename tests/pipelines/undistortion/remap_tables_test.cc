// The remap tables against the exact model and an independent ray tracer:
// a point's pixel, found in the tables (the output pixel whose entry is the
// point's pixel in the real image), is where the virtual pinhole projects
// the point when it lies at the design depth, and off by the reported
// error (ErrorAtDepth, the function the error maps are drawn from) at any
// other depth. Tolerance 0.01 px: the tables' float32 entries (1e-4 px at
// 2000 px) and bilinear interpolation of a smooth map (its second
// derivative over a pixel, < 1e-3 px here); the ray tracer's pixels agree
// with portcal's projection to 1e-6 px (housing_ground_truth_test).
#include "pipelines/undistortion/remap_tables.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/undistortion/approximation_error.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

// cv::remap's interpolation of a table at `at` (OpenCV's convention), in
// double precision.
double Bilinear(const cv::Mat& map, const Eigen::Vector2d& at) {
  const int c = std::clamp(static_cast<int>(std::floor(at.x())), 0, map.cols - 2);
  const int r = std::clamp(static_cast<int>(std::floor(at.y())), 0, map.rows - 2);
  const double fx = at.x() - c, fy = at.y() - r;
  const auto value = [&](int rr, int cc) { return static_cast<double>(map.at<float>(rr, cc)); };
  return (1 - fy) * ((1 - fx) * value(r, c) + fx * value(r, c + 1)) +
         fy * ((1 - fx) * value(r + 1, c) + fx * value(r + 1, c + 1));
}

// The output pixel (COLMAP's convention) whose table entry is
// `source_pixel`: Newton's method on the interpolated tables.
std::optional<Eigen::Vector2d> FindInTables(const RemapTables& tables,
                                            const Eigen::Vector2d& source_pixel,
                                            Eigen::Vector2d start) {
  Eigen::Vector2d u = start;
  const auto entry = [&](const Eigen::Vector2d& p) {
    const Eigen::Vector2d cv_pixel = p - Eigen::Vector2d(0.5, 0.5);
    return Eigen::Vector2d(Bilinear(tables.map_x, cv_pixel) + 0.5,
                           Bilinear(tables.map_y, cv_pixel) + 0.5);
  };
  for (int iteration = 0; iteration < 10; ++iteration) {
    const Eigen::Vector2d miss = entry(u) - source_pixel;
    if (miss.norm() < 1e-5) return u;
    Eigen::Matrix2d jacobian;
    const double h = 0.25;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d step = Eigen::Vector2d::Unit(k) * h;
      jacobian.col(k) = (entry(u + step) - entry(u - step)) / (2 * h);
    }
    u -= jacobian.inverse() * miss;
  }
  return std::nullopt;
}

// |found - pinhole projection| against ErrorAtDepth for points of the
// camera frame seen at known pixels; returns the largest difference.
double LargestDisagreement(const VirtualPinhole& pinhole, const RemapTables& tables,
                           const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector2d>>& points,
                           int* num_checked) {
  double largest = 0;
  for (const auto& [point, source_pixel] : points) {
    const std::optional<Eigen::Vector2d> projected = pinhole.PinholePixel(point);
    const std::optional<Eigen::Vector2d> start = pinhole.OutputPixel(source_pixel);
    if (!projected || !start || start->x() < 2 || start->y() < 2 ||
        start->x() > static_cast<double>(pinhole.pinhole.width) - 2 ||
        start->y() > static_cast<double>(pinhole.pinhole.height) - 2) {
      continue;
    }
    const std::optional<Eigen::Vector2d> found = FindInTables(tables, source_pixel, *start);
    EXPECT_TRUE(found) << source_pixel.transpose();
    if (!found) continue;
    const std::optional<double> reported = pinhole.ErrorAtDepth(*found, point.z());
    EXPECT_TRUE(reported);
    if (!reported) continue;
    largest = std::max(largest, std::abs((*found - *projected).norm() - *reported));
    ++*num_checked;
  }
  return largest;
}

Camera BenchCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 1300, 1920, 1080);
  camera.params = {1300, 1296, 975.5, 528.0, -0.12, 0.05, 0.0007, -0.0004};
  return camera;
}

TEST(RemapTables, EntriesAreTheExactSourcePixels) {
  const HousedCamera camera{
      BenchCamera(),
      Housing::FromName("DOMEPORT", {0.002, -0.001, 0.004, 0.05, 0.006, 1.0, 1.473, 1.334},
                        "test")};
  const VirtualPinhole pinhole = FitVirtualPinhole(camera, 1.5, Eigen::Matrix3d::Identity(), {});
  const RemapTables tables = ComputeRemapTables(pinhole, 2, NoProgress());
  ASSERT_EQ(tables.map_x.cols, static_cast<int>(pinhole.pinhole.width));
  ASSERT_EQ(tables.map_x.rows, static_cast<int>(pinhole.pinhole.height));
  for (int r = 0; r < tables.map_x.rows; r += 97) {
    for (int c = 0; c < tables.map_x.cols; c += 89) {
      const Eigen::Vector2d source = *pinhole.SourcePixel(Eigen::Vector2d(c + 0.5, r + 0.5));
      EXPECT_NEAR(tables.map_x.at<float>(r, c), source.x() - 0.5, 2e-4);
      EXPECT_NEAR(tables.map_y.at<float>(r, c), source.y() - 0.5, 2e-4);
    }
  }
}

TEST(RemapTables, PointsLandWhereThePinholeSaysWithinTheReportedError) {
  const double tilt = 5.0 * M_PI / 180.0;
  const HousedCamera camera{
      BenchCamera(),
      Housing::FromName(
          "FLATPORT", {std::sin(tilt), 0, std::cos(tilt), 0.02, 0.014, 1.0, 1.473, 1.334}, "test")};
  const VirtualPinhole pinhole = FitVirtualPinhole(camera, 1.2, Eigen::Matrix3d::Identity(), {});
  const RemapTables tables = ComputeRemapTables(pinhole, 2, NoProgress());
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> x(20, 1900), y(20, 1060);
  for (const double depth : {1.2, 0.4, 0.8, 3.0, 10.0}) {
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector2d>> points;
    for (int i = 0; i < 300; ++i) {
      // A point at this depth, projected through the exact model.
      const Eigen::Vector2d pixel(x(rng), y(rng));
      const std::optional<Eigen::Vector3d> point = pinhole.PointAtDepth(pixel, depth);
      ASSERT_TRUE(point);
      points.emplace_back(*point, *camera.Project(*point));
    }
    int num_checked = 0;
    const double disagreement = LargestDisagreement(pinhole, tables, points, &num_checked);
    std::printf("%.1f m: %d points, largest disagreement %.2e px, worst reported error %.3f px\n",
                depth, num_checked, disagreement,
                MeasureApproximationError(pinhole, {depth}, 16, 1).worst_px);
    EXPECT_LT(disagreement, 0.01) << depth << " m";
    EXPECT_GT(num_checked, 250) << depth << " m";
    if (depth == 1.2) {
      // At the design depth the reported error is zero: the pinhole is exact there.
      const ApproximationError error = MeasureApproximationError(pinhole, {depth}, 16, 1);
      EXPECT_LT(error.worst_px, 1e-6);
    }
  }
}

// The rendered sets' corners (an independent ray tracer's pixels), the
// design depth at each set's median corner depth.
TEST(RemapTables, RenderedCornersAgreeWithTheReportedError) {
  PORTCAL_REQUIRE_SHARED(shared);
  for (const char* set : {"chess_flatport", "chess_domeport"}) {
    const GroundTruth truth =
        ReadGroundTruth(shared / "datasets" / "rendered" / set / "ground_truth.yaml");
    ASSERT_TRUE(truth.housing) << set;
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector2d>> points;
    std::vector<double> depths;
    for (const FrameTruth& frame : truth.images) {
      for (size_t i = 0; i < truth.target.corners_3d.size(); ++i) {
        if (!frame.cam1.corners_px[i]) continue;
        points.emplace_back(frame.cam1.cam_from_target * truth.target.corners_3d[i],
                            *frame.cam1.corners_px[i]);
        depths.push_back(points.back().first.z());
      }
    }
    std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
    const HousedCamera camera{truth.camera, truth.housing};
    const VirtualPinhole pinhole =
        FitVirtualPinhole(camera, depths[depths.size() / 2], Eigen::Matrix3d::Identity(), {});
    const RemapTables tables = ComputeRemapTables(pinhole, 2, NoProgress());
    int num_checked = 0;
    const double disagreement = LargestDisagreement(pinhole, tables, points, &num_checked);
    std::printf("%s: %d corners, largest disagreement %.2e px\n", set, num_checked, disagreement);
    EXPECT_LT(disagreement, 0.01) << set;
    EXPECT_GT(num_checked, static_cast<int>(points.size()) / 2) << set;
  }
}

}  // namespace
}  // namespace portcal
