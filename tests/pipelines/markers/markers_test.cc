// The masker's enlarged marker quads and marker corners by edge fits.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pipelines/markers/aruco_markers.h"
#include "pipelines/markers/marker_edge_refinement.h"

namespace portcal {
namespace {

TEST(FeatureMasker, EnlargedQuadContainsItsScaledNeighbourhoodOnly) {
  const std::array<Eigen::Vector2d, 4> quad = {Eigen::Vector2d(10, 10), Eigen::Vector2d(20, 10),
                                               Eigen::Vector2d(20, 20), Eigen::Vector2d(10, 20)};
  EXPECT_TRUE(InsideEnlargedQuad(quad, 1.0, Eigen::Vector2d(15, 15)));
  EXPECT_FALSE(InsideEnlargedQuad(quad, 1.0, Eigen::Vector2d(21, 15)));
  EXPECT_TRUE(InsideEnlargedQuad(quad, 3.0, Eigen::Vector2d(29.9, 15)));   // centre 15 + 1.5 x 10
  EXPECT_FALSE(InsideEnlargedQuad(quad, 3.0, Eigen::Vector2d(30.1, 15)));
}

// A dark quad (a marker's border) on a light surround, sampled at 8 x 8
// points per pixel and area-averaged, then blurred: the exact corners are
// known; the edge fit must find them.
TEST(MarkerEdgeRefinement, FindsTheCornersOfABlurredMarker) {
  const int s = 8;
  cv::Mat big(160 * s, 160 * s, CV_8UC1, cv::Scalar(200));
  const std::array<Eigen::Vector2d, 4> truth = {Eigen::Vector2d(40.3, 45.2), Eigen::Vector2d(118.9, 38.7),
                                                Eigen::Vector2d(124.6, 117.5), Eigen::Vector2d(43.1, 121.8)};
  for (int r = 0; r < big.rows; ++r) {
    for (int c = 0; c < big.cols; ++c) {
      // COLMAP pixels of the sample.
      if (InsideEnlargedQuad(truth, 1.0, Eigen::Vector2d((c + 0.5) / s, (r + 0.5) / s))) {
        big.at<uint8_t>(r, c) = 30;
      }
    }
  }
  cv::Mat gray;
  cv::resize(big, gray, cv::Size(160, 160), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(gray, gray, cv::Size(0, 0), 1.2);
  std::array<cv::Point2d, 4> corners;
  for (int c = 0; c < 4; ++c) {
    // A rough start (as OpenCV's detector gives), OpenCV pixel convention.
    corners[c] = cv::Point2d(truth[c].x() - 0.5 + 0.6, truth[c].y() - 0.5 - 0.4);
  }
  MarkerEdgeRefinementOptions options;
  ASSERT_TRUE(RefineMarkerCorners(gray, options, &corners));
  for (int c = 0; c < 4; ++c) {
    // Sampling at 1/8 px leaves ~0.01 px of aliasing on an edge's position.
    EXPECT_NEAR(corners[c].x + 0.5, truth[c].x(), 0.03) << c;
    EXPECT_NEAR(corners[c].y + 0.5, truth[c].y(), 0.03) << c;
  }
}

}  // namespace
}  // namespace portcal
