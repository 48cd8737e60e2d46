// The masker's enlarged marker quads and marker corners by edge fits.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pipelines/markers/aruco_markers.h"
#include "pipelines/markers/edge_band_model.h"
#include "pipelines/markers/marker_edge_refinement.h"

namespace portcal {
namespace {

TEST(FeatureMasker, EnlargedQuadContainsItsScaledNeighbourhoodOnly) {
  const std::array<Eigen::Vector2d, 4> quad = {Eigen::Vector2d(10, 10), Eigen::Vector2d(20, 10),
                                               Eigen::Vector2d(20, 20), Eigen::Vector2d(10, 20)};
  EXPECT_TRUE(InsideEnlargedQuad(quad, 1.0, Eigen::Vector2d(15, 15)));
  EXPECT_FALSE(InsideEnlargedQuad(quad, 1.0, Eigen::Vector2d(21, 15)));
  EXPECT_TRUE(InsideEnlargedQuad(quad, 3.0, Eigen::Vector2d(29.9, 15)));  // centre 15 + 1.5 x 10
  EXPECT_FALSE(InsideEnlargedQuad(quad, 3.0, Eigen::Vector2d(30.1, 15)));
}

// A dark quad (a marker's border) on a light surround, sampled at 8 x 8
// points per pixel and area-averaged, then blurred: the exact corners are
// known. `shading` multiplies the gray by 1 - shading * x / width (a light's
// fall-off across the marker).
cv::Mat RenderQuad(const std::array<Eigen::Vector2d, 4>& truth, double blur, double shading) {
  const int s = 8, size = 160;
  cv::Mat big(size * s, size * s, CV_8UC1);
  for (int r = 0; r < big.rows; ++r) {
    for (int c = 0; c < big.cols; ++c) {
      // COLMAP pixels of the sample.
      const Eigen::Vector2d xy((c + 0.5) / s, (r + 0.5) / s);
      const double level = InsideEnlargedQuad(truth, 1.0, xy) ? 30 : 200;
      big.at<uint8_t>(r, c) = cv::saturate_cast<uint8_t>(level * (1 - shading * xy.x() / size));
    }
  }
  cv::Mat gray;
  cv::resize(big, gray, cv::Size(size, size), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(gray, gray, cv::Size(0, 0), blur);
  return gray;
}

// OpenCV's corners of a foreshortened marker can be a pixel or two off:
// the start here is (0.6, -0.4) px off, or (1.5, 1.2) px.
std::array<cv::Point2d, 4> RoughStart(const std::array<Eigen::Vector2d, 4>& truth, bool far) {
  std::array<cv::Point2d, 4> corners;
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector2d off =
        far ? Eigen::Vector2d(c % 2 ? 1.5 : -1.5, c < 2 ? 1.2 : -1.2) : Eigen::Vector2d(0.6, -0.4);
    corners[c] =
        cv::Point2d(truth[c].x() - 0.5 + off.x(), truth[c].y() - 0.5 + off.y());  // OpenCV pixels
  }
  return corners;
}

// Sampling at 1/8 px leaves ~0.01 px of aliasing on an edge's position.
void ExpectCorners(const std::array<cv::Point2d, 4>& corners,
                   const std::array<Eigen::Vector2d, 4>& truth, double tolerance) {
  for (int c = 0; c < 4; ++c) {
    EXPECT_NEAR(corners[c].x + 0.5, truth[c].x(), tolerance) << c;
    EXPECT_NEAR(corners[c].y + 0.5, truth[c].y(), tolerance) << c;
  }
}

const std::array<Eigen::Vector2d, 4> kMarker = {
    Eigen::Vector2d(40.3, 45.2), Eigen::Vector2d(118.9, 38.7), Eigen::Vector2d(124.6, 117.5),
    Eigen::Vector2d(43.1, 121.8)};

// The band model's derivatives written out against central differences of
// its cost: J^T r is the cost's gradient, and J^T J's diagonal the sum of
// the squared residual derivatives, for an edge oblique to the pixel grid,
// quadratic along the side, with shaded levels.
TEST(EdgeBandModel, DerivativesMatchCentralDifferences) {
  EdgeBandModel model;
  model.n = Eigen::Vector2d(0.6, 0.8);
  model.quadratic = true;
  std::vector<BandPixel> band;
  for (int k = 0; k < 60; ++k) {
    const double t = (k % 12 + 0.5) / 12, s = -2.5 + 0.09 * k;
    band.push_back({t, s, 120 + 60 * std::tanh(s - 0.2) + 3 * std::sin(7.0 * k)});
  }
  const std::vector<char> use(band.size(), 1);
  EdgeBandModel::Params q;
  q << 0.15, -0.3, 0.4, 118, 6, 55, -9, std::log(0.9);
  EdgeBandModel::Normal jtj;
  EdgeBandModel::Params jtr;
  model.Linearise(band, use, q, &jtj, &jtr);
  const auto residual = [&](const EdgeBandModel::Params& at, size_t i) {
    double u0;
    ErfPixelAverage m;
    return model.Residual(band[i], at, &u0, &m);
  };
  for (int j = 0; j < EdgeBandModel::kNumParams; ++j) {
    const double h = 1e-6;
    EdgeBandModel::Params up = q, down = q;
    up[j] += h;
    down[j] -= h;
    double gradient = 0, squared = 0;
    for (size_t i = 0; i < band.size(); ++i) {
      const double derivative = (residual(up, i) - residual(down, i)) / (2 * h);
      gradient += residual(q, i) * derivative;
      squared += derivative * derivative;
    }
    EXPECT_NEAR(jtr[j], gradient, 1e-5 * (1 + std::abs(gradient))) << "parameter " << j;
    EXPECT_NEAR(jtj(j, j), squared, 1e-5 * (1 + squared)) << "parameter " << j;
  }
}

TEST(MarkerEdgeRefinement, FindsTheCornersOfABlurredMarker) {
  const cv::Mat gray = RenderQuad(kMarker, 1.2, 0);
  std::array<cv::Point2d, 4> corners = RoughStart(kMarker, false);
  ASSERT_TRUE(RefineMarkerCorners(gray, MarkerEdgeRefinementOptions(), &corners));
  ExpectCorners(corners, kMarker, 0.03);
}

// Shading: the levels fall by 40 % across the marker. With levels held
// constant along a side, their trend went into the edges' slopes and the
// corners moved by 0.2-0.3 px.
TEST(MarkerEdgeRefinement, FindsTheCornersOfAShadedMarker) {
  const cv::Mat gray = RenderQuad(kMarker, 0.8, 0.4);
  std::array<cv::Point2d, 4> corners = RoughStart(kMarker, false);
  ASSERT_TRUE(RefineMarkerCorners(gray, MarkerEdgeRefinementOptions(), &corners));
  ExpectCorners(corners, kMarker, 0.03);
}

// A marker seen obliquely (modules ~4 px across its long sides) from a
// start 1.9 px off: the bands laid about the start hold the edge
// off-centre; laid again about the fitted corners, they find it.
TEST(MarkerEdgeRefinement, FindsTheCornersOfAForeshortenedMarkerFromAFarStart) {
  const std::array<Eigen::Vector2d, 4> oblique = {
      Eigen::Vector2d(30.4, 60.2), Eigen::Vector2d(130.7, 52.9), Eigen::Vector2d(132.1, 78.3),
      Eigen::Vector2d(31.6, 84.8)};
  const cv::Mat gray = RenderQuad(oblique, 0.7, 0);
  std::array<cv::Point2d, 4> corners = RoughStart(oblique, true);
  ASSERT_TRUE(RefineMarkerCorners(gray, MarkerEdgeRefinementOptions(), &corners));
  ExpectCorners(corners, oblique, 0.05);
}

// Modules of ~1.7 px across the long sides: the band would hold the bits
// (and the edge's blur); refused, corners untouched.
TEST(MarkerEdgeRefinement, RefusesAMarkerTooForeshortenedToFit) {
  const std::array<Eigen::Vector2d, 4> edge_on = {
      Eigen::Vector2d(30.4, 60.2), Eigen::Vector2d(130.7, 57.9), Eigen::Vector2d(131.1, 68.3),
      Eigen::Vector2d(30.6, 70.5)};
  const cv::Mat gray = RenderQuad(edge_on, 0.7, 0);
  std::array<cv::Point2d, 4> corners = RoughStart(edge_on, false);
  const std::array<cv::Point2d, 4> start = corners;
  EXPECT_FALSE(RefineMarkerCorners(gray, MarkerEdgeRefinementOptions(), &corners));
  for (int c = 0; c < 4; ++c) EXPECT_EQ(corners[c], start[c]) << c;
}

}  // namespace
}  // namespace portcal
