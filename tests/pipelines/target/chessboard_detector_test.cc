// The chessboard detector on drawn boards with known corners: a view whose
// corners near the image's edge cannot be fitted keeps the others and says
// why; the X-junction count sees a board square to the image and not a
// cluttered scene; too few corners refuse the view.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "pipelines/target/chessboard_detector.h"
#include "pipelines/target/x_corner_count.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

constexpr int kCols = 8, kRows = 6, kSquare = 40;
constexpr int kLeft = 20, kTop = 80;  // the board's outer top-left corner

// A board square to the image, blurred by 1 px; inner corner (r, c) at
// COLMAP pixel (kLeft + (c + 1) kSquare, kTop + (r + 1) kSquare): the
// squares' edges lie on pixel boundaries.
cv::Mat DrawnBoard(int width, int height) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(200));
  for (int r = 0; r <= kRows; ++r) {
    for (int c = 0; c <= kCols; ++c) {
      if ((r + c) % 2 != 0) continue;
      cv::rectangle(image, cv::Rect(kLeft + c * kSquare, kTop + r * kSquare, kSquare, kSquare), cv::Scalar(40),
                    cv::FILLED);
    }
  }
  cv::GaussianBlur(image, image, cv::Size(), 1.0);
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
  EXPECT_NE(detection.note.find("6 of 48 corners left out (6 window beyond the image)"), std::string::npos)
      << detection.note;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const auto& corner = detection.corners[r * kCols + c];
      // Either order of a symmetric board: compare with the nearer truth.
      const Eigen::Vector2d truth(kLeft + (c + 1) * kSquare, kTop + (r + 1) * kSquare);
      const Eigen::Vector2d turned(kLeft + (kCols - c) * kSquare, kTop + (kRows - r) * kSquare);
      if (!corner) continue;
      EXPECT_LT(std::min((*corner - truth).norm(), (*corner - turned).norm()), 0.02) << r << "," << c;
    }
  }
}

TEST(ChessboardDetector, RefusesAViewWithTooFewCornersForAPose) {
  const int width = kLeft + kCols * kSquare + 8;
  ChessboardDetectionOptions options = Options();
  options.min_refined_corners = kCols * kRows - kRows + 1;
  const ChessboardDetection detection = DetectChessboard(DrawnBoard(width, 480), options);
  EXPECT_FALSE(detection.found);
  EXPECT_NE(detection.reason.find("too few corners for a pose"), std::string::npos) << detection.reason;
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
