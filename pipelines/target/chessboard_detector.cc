#include "pipelines/target/chessboard_detector.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/error.h"

namespace portcal {

void ChessboardDetectionOptions::Check() const {
  if (cols < 2) throw OptionError("--Target.cols", std::to_string(cols), ">= 2 inner corners");
  if (rows < 2) throw OptionError("--Target.rows", std::to_string(rows), ">= 2 inner corners");
  if (coarse_max_image_size < 0) {
    throw OptionError("--Target.coarse_max_image_size", std::to_string(coarse_max_image_size), ">= 0");
  }
  if (!(min_refined_fraction > 0 && min_refined_fraction <= 1)) {
    throw OptionError("--Target.min_refined_fraction", std::to_string(min_refined_fraction), "(0, 1]");
  }
  refinement.Check();
}

namespace {

// The board's corners in OpenCV's pixels of the image scaled by *scale.
// OpenCV's classic detector first, on the halved image and then at full
// resolution: on the real views it finds boards the SB detector misses, an
// order of magnitude faster (docs/benchmarks.md), and its fast check turns
// plain images without the board away quickly (textured ones pass it and
// stay slow). Only then the SB detector (exhaustive) at each scale, so that
// its cost falls on the images the classic one misses.
bool FindCoarse(const cv::Mat& gray, const ChessboardDetectionOptions& options, std::vector<cv::Point2f>* corners,
                double* scale) {
  const cv::Size pattern(options.cols, options.rows);
  std::vector<std::pair<double, cv::Mat>> levels;
  const int longer = std::max(gray.cols, gray.rows);
  if (options.coarse_max_image_size > 0 && longer > options.coarse_max_image_size) {
    // Halved until it fits: INTER_AREA by a power of two is a plain box
    // average, several times faster than by any other factor.
    double factor = 1.0;
    while (longer * factor > options.coarse_max_image_size) factor /= 2;
    cv::Mat small;
    cv::resize(gray, small, cv::Size(), factor, factor, cv::INTER_AREA);
    levels.emplace_back(factor, small);
  }
  levels.emplace_back(1.0, gray);
  for (const auto& [factor, image] : levels) {
    if (cv::findChessboardCorners(image, pattern, *corners,
                                  cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK)) {
      *scale = factor;
      return true;
    }
  }
  for (const auto& [factor, image] : levels) {
    if (cv::findChessboardCornersSB(image, pattern, *corners, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
      *scale = factor;
      return true;
    }
  }
  return false;
}

// Mean gray of the first square inside the grid at corner 0 (between
// corners 0, 1, cols and cols + 1). It has the colour of the square
// diagonally outside corner 0 and, unlike that one, always lies on the
// board (the outer ring may be cut, or printed differently).
double FirstSquareGray(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols) {
  const Eigen::Vector2d centre = 0.25 * (corners[0] + corners[1] + corners[cols] + corners[cols + 1]);
  const double radius = 0.15 * std::min((corners[1] - corners[0]).norm(), (corners[cols] - corners[0]).norm());
  double sum = 0;
  int count = 0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const Eigen::Vector2d p = centre + radius * 0.5 * Eigen::Vector2d(dx, dy);
      sum += gray.at<uint8_t>(std::clamp(static_cast<int>(p.y()), 0, gray.rows - 1),
                              std::clamp(static_cast<int>(p.x()), 0, gray.cols - 1));
      ++count;
    }
  }
  return sum / count;
}

// True when the far end's first square (at corner n - 1) is the darker:
// corner 0's diagonal squares are to be the black ones. The two ends are
// compared with each other, not each with the board's mean gray: on the
// OpenCV stereo sample both ends read lighter than the mean, and the answer
// then followed OpenCV's start (the two cameras labelled one board
// differently).
bool FarEndIsBlack(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols) {
  const std::vector<Eigen::Vector2d> reversed(corners.rbegin(), corners.rend());
  return FirstSquareGray(gray, reversed, cols) < FirstSquareGray(gray, corners, cols);
}

}  // namespace

ChessboardDetection DetectChessboard(const cv::Mat& gray, const ChessboardDetectionOptions& options) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  ChessboardDetection detection;
  std::vector<cv::Point2f> coarse;
  double scale = 1.0;
  const bool found = FindCoarse(gray, options, &coarse, &scale);
  if (!found) {
    detection.reason = "no " + std::to_string(options.cols) + "x" + std::to_string(options.rows) +
                       " inner-corner chessboard found";
    return detection;
  }
  // Back to full-resolution COLMAP pixels: OpenCV's (0, 0) is the centre of
  // the top-left pixel, also in the downscaled image.
  std::vector<Eigen::Vector2d> start;
  for (const cv::Point2f& p : coarse) start.emplace_back((p.x + 0.5) / scale, (p.y + 0.5) / scale);

  // Right-handed order: the rows run to the right of the columns as the
  // board is seen from the front (target x cross y away from the camera).
  // findChessboardCorners may return the mirror image, a labelling no board
  // pose can give, which breaks the correspondence between two cameras'
  // views of one board.
  const Eigen::Vector2d along_row = start[1] - start[0], along_column = start[options.cols] - start[0];
  if (along_row.x() * along_column.y() - along_row.y() * along_column.x() < 0) {
    for (int r = 0; r < options.rows; ++r) {
      std::reverse(start.begin() + r * options.cols, start.begin() + (r + 1) * options.cols);
    }
  }
  // Canonical order: corner 0's outer diagonal square is black. OpenCV may
  // start at the far corner (the same grid rotated by 180 degrees).
  const int squares = (options.cols + 1) + (options.rows + 1);
  detection.symmetric = squares % 2 == 0;
  if (FarEndIsBlack(gray, start, options.cols)) std::reverse(start.begin(), start.end());

  const auto refined = RefineChessboardCorners(gray, start, options.cols, options.rows, options.refinement);
  detection.corners.resize(refined.size());
  for (size_t i = 0; i < refined.size(); ++i) {
    if (refined[i]) {
      detection.corners[i] = refined[i]->xy;
      ++detection.num_refined;
    }
  }
  const int needed = static_cast<int>(std::ceil(options.min_refined_fraction * refined.size()));
  if (detection.num_refined < needed) {
    detection.reason = "only " + std::to_string(detection.num_refined) + " of " +
                       std::to_string(refined.size()) + " corners refined (blur, low contrast?)";
    return detection;
  }
  detection.found = true;
  return detection;
}

}  // namespace portcal
