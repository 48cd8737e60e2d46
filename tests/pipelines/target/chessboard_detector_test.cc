// The chessboard detector on drawn boards with known corners: a view whose
// corners near the image's edge cannot be fitted keeps the others and says
// why; a board cut by the image's border keeps its corners in view where
// their place on the board can be told, and is refused otherwise; the
// X-junction count sees a board square to the image and not a cluttered
// scene; too few corners refuse the view.
#include "pipelines/target/chessboard_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "pipelines/target/x_corner_count.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

constexpr int kCols = 8, kRows = 6, kSquare = 40;
constexpr int kLeft = 20, kTop = 80;  // the board's outer top-left corner

// A board square to the image, blurred by 1 px; inner corner (r, c) at
// COLMAP pixel (kLeft + (c + 1) kSquare, kTop + (r + 1) kSquare): the
// squares' edges lie on pixel boundaries.
// The black squares of a board of squares_x x squares_y squares whose
// outer top-left corner is at (left, top), square (0, 0) black; blurred by
// 1 px.
void DrawSquares(int squares_x, int squares_y, int left, int top, cv::Mat* image) {
  for (int r = 0; r < squares_y; ++r) {
    for (int c = 0; c < squares_x; ++c) {
      if ((r + c) % 2 != 0) continue;
      cv::rectangle(*image, cv::Rect(left + c * kSquare, top + r * kSquare, kSquare, kSquare),
                    cv::Scalar(40), cv::FILLED);
    }
  }
  cv::GaussianBlur(*image, *image, cv::Size(), 1.0);
}

cv::Mat DrawnBoard(int width, int height) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(200));
  DrawSquares(kCols + 1, kRows + 1, kLeft, kTop, &image);
  return image;
}

ChessboardDetectionOptions Options() {
  ChessboardDetectionOptions options;
  options.cols = kCols;
  options.rows = kRows;
  return options;
}

TEST(ChessboardDetector, KeepsTheCornersThatRefineAndSaysWhyTheOthersWereLeftOut) {
  // The last column of inner corners 8 px from the right edge: its fit
  // windows (16 px) reach beyond the image.
  const int width = kLeft + kCols * kSquare + 8;
  const ChessboardDetection detection = DetectChessboard(DrawnBoard(width, 480), Options());
  ASSERT_TRUE(detection.found) << detection.reason;
  EXPECT_EQ(detection.num_refined, kCols * kRows - kRows);
  EXPECT_NE(detection.note.find("6 of 48 corners left out (6 window beyond the image)"),
            std::string::npos)
      << detection.note;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const auto& corner = detection.corners[r * kCols + c];
      // Either order of a symmetric board: compare with the nearer truth.
      const Eigen::Vector2d truth(kLeft + (c + 1) * kSquare, kTop + (r + 1) * kSquare);
      const Eigen::Vector2d turned(kLeft + (kCols - c) * kSquare, kTop + (kRows - r) * kSquare);
      if (!corner) continue;
      EXPECT_LT(std::min((*corner - truth).norm(), (*corner - turned).norm()), 0.02)
          << r << "," << c;
    }
  }
}

TEST(ChessboardDetector, RefusesAViewWithTooFewCornersForAPose) {
  const int width = kLeft + kCols * kSquare + 8;
  ChessboardDetectionOptions options = Options();
  options.min_refined_corners = kCols * kRows - kRows + 1;
  const ChessboardDetection detection = DetectChessboard(DrawnBoard(width, 480), options);
  EXPECT_FALSE(detection.found);
  EXPECT_NE(detection.reason.find("too few corners for a pose"), std::string::npos)
      << detection.reason;
}

// A 9 x 6 board (10 x 7 squares: it does not look the same turned by 180
// degrees), square to the image, its outer top-left corner at (left, top);
// canonical corner (r, c) at (left + (c + 1) kSquare, top + (r + 1) kSquare).
cv::Mat DrawnAsymmetricBoard(int width, int height, int left, int top) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(120));
  cv::rectangle(image, cv::Rect(left - 15, top - 15, 10 * kSquare + 30, 7 * kSquare + 30),
                cv::Scalar(200), cv::FILLED);
  DrawSquares(10, 7, left, top, &image);
  return image;
}

ChessboardDetectionOptions AsymmetricOptions() {
  ChessboardDetectionOptions options;
  options.cols = 9;
  options.rows = 6;
  return options;
}

// Of a 9 x 6 board drawn at (left, top) and cut after its 6th column:
// exactly the corners of columns 0-5, each within `tolerance` px of where
// it is drawn.
void ExpectColumnsInView(const ChessboardDetection& detection, int left, int top,
                         double tolerance) {
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) {
      const auto& corner = detection.corners[r * 9 + c];
      ASSERT_EQ(corner.has_value(), c < 6) << r << "," << c;
      if (corner) {
        EXPECT_LT(
            (*corner - Eigen::Vector2d(left + (c + 1) * kSquare, top + (r + 1) * kSquare)).norm(),
            tolerance);
      }
    }
  }
}

// Cut by the image's right border, the board's part in view is placed by
// its left edge: the 6 columns in view, each corner where it is drawn.
TEST(PartialChessboard, ABoardCutByTheImagesBorderKeepsTheCornersInView) {
  const int left = 30, top = 60;
  const int width = left + 6 * kSquare + 25;  // inner columns 0-5 in view, 6-8 beyond
  const ChessboardDetection detection =
      DetectChessboard(DrawnAsymmetricBoard(width, 400, left, top), AsymmetricOptions());
  ASSERT_TRUE(detection.found) << detection.reason;
  EXPECT_TRUE(detection.partial);
  EXPECT_FALSE(detection.symmetric);
  EXPECT_EQ(detection.num_refined, 6 * 6);
  EXPECT_NE(detection.note.find("18 out of view"), std::string::npos) << detection.note;
  ExpectColumnsInView(detection, left, top, 0.02);
}

// The quick mode (live views) keeps the same corners of a cut board, to
// tenths of a pixel.
TEST(PartialChessboard, QuickModeKeepsTheCornersInViewToo) {
  const int left = 30, top = 60;
  ChessboardDetectionOptions options = AsymmetricOptions();
  options.precise_fit = false;
  const ChessboardDetection detection =
      DetectChessboard(DrawnAsymmetricBoard(left + 6 * kSquare + 25, 400, left, top), options);
  ASSERT_TRUE(detection.found) << detection.reason;
  EXPECT_TRUE(detection.partial);
  EXPECT_EQ(detection.num_refined, 6 * 6);
  ExpectColumnsInView(detection, left, top, 0.3);
}

// Cut on both sides, which of the board's columns are in view cannot be
// told: refused, saying so.
TEST(PartialChessboard, AStripCutOnBothSidesIsRefused) {
  const int left = -3 * kSquare + 10, top = 60;
  const ChessboardDetection detection =
      DetectChessboard(DrawnAsymmetricBoard(5 * kSquare, 400, left, top), AsymmetricOptions());
  EXPECT_FALSE(detection.found);
  EXPECT_NE(detection.reason.find("cannot be told"), std::string::npos) << detection.reason;
}

// Ending inside the image at an occluder, the board's part cannot be
// placed: no corner is given a wrong place on the board.
TEST(PartialChessboard, ABoardEndingAtAnOccluderGetsNoWrongCorners) {
  const int left = 30, top = 60;
  cv::Mat image = DrawnAsymmetricBoard(640, 400, left, top);
  cv::rectangle(image, cv::Rect(left + 7 * kSquare - 20, 0, 640, 400), cv::Scalar(110), cv::FILLED);
  const ChessboardDetection detection = DetectChessboard(image, AsymmetricOptions());
  if (!detection.found) {
    EXPECT_FALSE(detection.reason.empty());
    return;
  }
  for (size_t i = 0; i < detection.corners.size(); ++i) {
    const int r = static_cast<int>(i) / 9, c = static_cast<int>(i) % 9;
    if (detection.corners[i]) {
      EXPECT_LT((*detection.corners[i] -
                 Eigen::Vector2d(left + (c + 1) * kSquare, top + (r + 1) * kSquare))
                    .norm(),
                0.05);
    }
  }
}

TEST(XCornerCount, SeesABoardSquareToTheImageAndNotAClutteredScene) {
  // Junctions between pixels, edges along the ring's samples: the case a
  // ring sampled one way only misses entirely. All but the outer rows and
  // columns of inner corners are grid crossings.
  EXPECT_EQ(CountXCorners(DrawnBoard(640, 480)), (kCols - 2) * (kRows - 2));
  const int cluttered = CountXCorners(testing::ClutteredScene(1280, 720, 5));
  std::cout << "grid junctions in the cluttered scene: " << cluttered << "\n";
  // Fewer than the detector asks of the smallest board it is given here.
  EXPECT_LT(cluttered, std::ceil(Options().min_x_corner_fraction * (kCols - 2) * (kRows - 2)));
  cv::Mat noise(480, 640, CV_8UC1);
  cv::randu(noise, 80, 140);
  EXPECT_FALSE(DetectChessboard(noise, Options()).found);
  cv::Mat tiny(8, 8, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(CountXCorners(tiny), 0);
  EXPECT_FALSE(DetectChessboard(tiny, Options()).found);
}

}  // namespace
}  // namespace portcal
