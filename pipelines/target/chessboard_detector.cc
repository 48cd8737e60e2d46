#include "pipelines/target/chessboard_detector.h"

#include <map>
#include <set>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/error.h"
#include "pipelines/target/coarse_level.h"

namespace portcal {

void ChessboardDetectionOptions::Check() const {
  if (cols < 2) throw OptionError("--Target.cols", std::to_string(cols), ">= 2 inner corners");
  if (rows < 2) throw OptionError("--Target.rows", std::to_string(rows), ">= 2 inner corners");
  if (coarse_max_image_size < 0) {
    throw OptionError("--Target.coarse_max_image_size", std::to_string(coarse_max_image_size), ">= 0");
  }
  if (!(min_x_corner_fraction >= 0 && min_x_corner_fraction <= 1)) {
    throw OptionError("--Target.min_x_corner_fraction", std::to_string(min_x_corner_fraction), "[0, 1]");
  }
  if (min_refined_corners < 4) {
    throw OptionError("--Target.min_refined_corners", std::to_string(min_refined_corners), ">= 4");
  }
  refinement.Check();
}

namespace {

// The board's corners in OpenCV's pixels of the image scaled by *scale; or
// false with the reason. First the X-junction count on the coarse level:
// an image without enough of them is not searched. Then OpenCV's classic
// detector on the coarse level without its fast check (which misses small
// boards there and which the count replaces), at full resolution with it;
// the classic detector finds boards on the real views that the SB detector
// misses, an order of magnitude faster (docs/benchmarks.md). Only then the
// SB detector (exhaustive) at each scale, so that its cost falls on the
// images the classic one misses.
bool FindCoarse(const cv::Mat& gray, const ChessboardDetectionOptions& options, std::vector<cv::Point2f>* corners,
                double* scale, std::string* reason) {
  const cv::Size pattern(options.cols, options.rows);
  std::vector<std::pair<double, cv::Mat>> levels = {CoarseLevel(gray, options.coarse_max_image_size)};
  if (levels.front().first < 1) levels.emplace_back(1.0, gray);
  const int num_crossings = std::max(options.cols - 2, 1) * std::max(options.rows - 2, 1);
  const int needed = static_cast<int>(std::ceil(options.min_x_corner_fraction * num_crossings));
  if (needed > 0) {
    const int count = CountXCorners(levels.front().second, {}, needed);
    if (count < needed) {
      *reason = "no " + std::to_string(options.cols) + "x" + std::to_string(options.rows) +
                " inner-corner chessboard in view (" + std::to_string(count) +
                " chessboard-like grid junctions, fewer than " + std::to_string(needed) + ")";
      return false;
    }
  }
  // On the coarse level a global threshold first (a few ms where the
  // adaptive one took up to 0.2 s on a render; docs/benchmarks.md), then
  // the adaptive one; at full size the adaptive one with the fast check.
  const int adaptive = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
  std::vector<std::pair<size_t, int>> attempts = {{0, cv::CALIB_CB_NORMALIZE_IMAGE},
                                                  {0, adaptive | (needed > 0 ? 0 : cv::CALIB_CB_FAST_CHECK)}};
  if (levels.size() > 1) attempts.emplace_back(1, adaptive | cv::CALIB_CB_FAST_CHECK);
  for (const auto& [level, flags] : attempts) {
    if (cv::findChessboardCorners(levels[level].second, pattern, *corners, flags)) {
      *scale = levels[level].first;
      return true;
    }
  }
  for (const auto& [factor, image] : levels) {
    if (cv::findChessboardCornersSB(image, pattern, *corners, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
      *scale = factor;
      return true;
    }
  }
  *reason = "no " + std::to_string(options.cols) + "x" + std::to_string(options.rows) +
            " inner-corner chessboard found";
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

// "3 of 48 corners left out (2 no contrast, 1 window beyond the image)".
std::string LeftOutNote(const std::vector<CornerFailure>& failures) {
  std::map<CornerFailure, int> counts;
  for (const CornerFailure failure : failures) {
    if (failure != CornerFailure::kNone) ++counts[failure];
  }
  int total = 0;
  std::string reasons;
  for (const auto& [failure, count] : counts) {
    reasons += (reasons.empty() ? "" : ", ") + std::to_string(count) + " " + CornerFailureText(failure);
    total += count;
  }
  return std::to_string(total) + " of " + std::to_string(failures.size()) + " corners left out" +
         (reasons.empty() ? "" : " (" + reasons + ")");
}

// cv::cornerSubPix at full resolution on corners in COLMAP pixels.
void PolishQuickly(const cv::Mat& gray, std::vector<Eigen::Vector2d>* corners) {
  std::vector<cv::Point2f> points;
  for (const Eigen::Vector2d& c : *corners) points.emplace_back(c.x() - 0.5, c.y() - 0.5);
  cv::cornerSubPix(gray, points, cv::Size(2, 2), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10, 0.01));
  for (size_t i = 0; i < points.size(); ++i) (*corners)[i] = Eigen::Vector2d(points[i].x + 0.5, points[i].y + 0.5);
}

}  // namespace

ChessboardDetection DetectChessboard(const cv::Mat& gray, const ChessboardDetectionOptions& options) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  ChessboardDetection detection;
  std::vector<cv::Point2f> coarse;
  double scale = 1.0;
  if (!FindCoarse(gray, options, &coarse, &scale, &detection.reason)) return detection;
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

  if (!options.precise_fit) {
    PolishQuickly(gray, &start);
    for (const Eigen::Vector2d& corner : start) detection.corners.emplace_back(corner);
    detection.num_refined = static_cast<int>(start.size());
    detection.found = true;
    return detection;
  }
  // The coarse corners are as good as their level's pixels: a corner may
  // move by the refinement's maximum in those pixels.
  CornerRefinementOptions refinement = options.refinement;
  refinement.max_shift_px /= scale;
  std::vector<CornerFailure> failures;
  const auto refined = RefineChessboardCorners(gray, start, options.cols, options.rows, refinement, &failures);
  detection.corners.resize(refined.size());
  std::set<int> rows, cols;
  for (size_t i = 0; i < refined.size(); ++i) {
    if (!refined[i]) continue;
    detection.corners[i] = refined[i]->xy;
    ++detection.num_refined;
    rows.insert(static_cast<int>(i) / options.cols);
    cols.insert(static_cast<int>(i) % options.cols);
  }
  const std::string left_out = LeftOutNote(failures);
  if (detection.num_refined < options.min_refined_corners || rows.size() < 2 || cols.size() < 2) {
    detection.reason = "board found but too few corners for a pose: " + left_out;
    return detection;
  }
  detection.found = true;
  if (detection.num_refined < static_cast<int>(refined.size())) detection.note = left_out;
  return detection;
}

}  // namespace portcal
