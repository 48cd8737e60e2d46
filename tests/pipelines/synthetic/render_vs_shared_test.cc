// portcal's renderer against the independent ray tracer of
// ../shared/datasets/rendered: the same camera, housing, board and pose must
// give the same image up to the shared renders' noise (sigma = 1 gray level)
// and 8-bit rounding.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/synthetic/renderer.h"
#include "pipelines/synthetic/target_builder.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

class RenderVsShared : public ::testing::TestWithParam<std::string> {};

// Least-squares shift d (px) with theirs - ours ~ grad(ours) . d: where the
// two renders put the edges relative to each other.
Eigen::Vector2d EdgeShift(const cv::Mat& ours, const cv::Mat& diff) {
  cv::Mat image, gx, gy;
  ours.convertTo(image, CV_32F);
  cv::Sobel(image, gx, CV_32F, 1, 0, 3, 1.0 / 8);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3, 1.0 / 8);
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (int r = 1; r < image.rows - 1; ++r) {
    for (int c = 1; c < image.cols - 1; ++c) {
      const Eigen::Vector2d g(gx.at<float>(r, c), gy.at<float>(r, c));
      normal += g * g.transpose();
      rhs += g * diff.at<double>(r, c);
    }
  }
  return normal.ldlt().solve(rhs);
}

TEST_P(RenderVsShared, SameImageUpToNoise) {
  PORTCAL_REQUIRE_SHARED(shared);
  const std::filesystem::path dir = shared / "datasets/rendered" / GetParam();
  if (!std::filesystem::exists(dir / "ground_truth.yaml")) GTEST_SKIP() << dir << " absent";
  const GroundTruth truth = ReadGroundTruth(dir / "ground_truth.yaml");
  TargetOptions target_options;
  target_options.cols = truth.target.inner_corners_cols;
  target_options.rows = truth.target.inner_corners_rows;
  target_options.square_size_m = truth.target.square_size;
  target_options.margin_m = truth.target.margin;
  const ImageTruth& view = truth.images[0].cam1;
  const cv::Mat theirs = cv::imread((dir / view.file).string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(theirs.empty());
  // The shared renders behave like a denser box filter than 4 x 4 stratum
  // centres (16 x 16 samples reproduce them to their noise, RMS 1.047, but
  // take 12 GB of rays at 1920 x 1080): at the default 4 x 4 the RMS grows by
  // the coarser anti-aliasing only, and the edges sit in the same place.
  for (const int spp : {4}) {
    ImageFormationOptions render;
    render.spp = spp;
    render.noise_sigma = 0;  // compare with the noise-free image
    const BuiltTarget target = BuildTarget(target_options, render.levels);
    const RayMap rays(truth.camera, truth.housing ? &*truth.housing : nullptr, spp, 2);
    const cv::Mat ours =
        RenderImage(rays, {{target.object.get(), view.cam_from_target}}, render, 0);
    cv::Mat diff;
    cv::subtract(theirs, ours, diff, cv::noArray(), CV_64F);
    cv::Scalar mean, stddev;
    cv::meanStdDev(diff, mean, stddev);
    // Noise sigma 1 plus the rounding of both images: RMS sqrt(1 + 2/12).
    EXPECT_NEAR(mean[0], 0.0, 0.01) << "spp " << spp;
    EXPECT_LT(stddev[0], 1.15) << "spp " << spp;
    // Edges in the same place: no shift beyond 0.002 px.
    const Eigen::Vector2d shift = EdgeShift(ours, diff);
    EXPECT_LT(shift.norm(), 2e-3) << "spp " << spp << " shift " << shift.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(RenderedSets, RenderVsShared,
                         ::testing::Values("chess_air_distorted", "chess_domeport",
                                           "chess_flatport"));

}  // namespace
}  // namespace portcal
