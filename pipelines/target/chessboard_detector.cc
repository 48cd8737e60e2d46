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

bool FindCoarse(const cv::Mat& gray, const cv::Size& pattern, std::vector<cv::Point2f>* corners) {
  if (cv::findChessboardCornersSB(gray, pattern, *corners,
                                  cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE)) {
    return true;
  }
  return cv::findChessboardCorners(gray, pattern, *corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
}

// Mean gray of the square diagonally outside corner 0 (its centre is corner
// 0 minus half a step along the row and along the column).
double OuterDiagonalGray(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols) {
  const Eigen::Vector2d centre =
      corners[0] - 0.5 * ((corners[1] - corners[0]) + (corners[cols] - corners[0]));
  const double radius = 0.15 * std::min((corners[1] - corners[0]).norm(), (corners[cols] - corners[0]).norm());
  double sum = 0;
  int count = 0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const Eigen::Vector2d p = centre + radius * 0.5 * Eigen::Vector2d(dx, dy);
      const int c = static_cast<int>(p.x()), r = static_cast<int>(p.y());
      if (c < 0 || r < 0 || c >= gray.cols || r >= gray.rows) continue;
      sum += gray.at<uint8_t>(r, c);
      ++count;
    }
  }
  return count > 0 ? sum / count : -1;
}

double MeanCornerGray(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners) {
  double sum = 0;
  for (const auto& c : corners) {
    sum += gray.at<uint8_t>(std::clamp(static_cast<int>(c.y()), 0, gray.rows - 1),
                            std::clamp(static_cast<int>(c.x()), 0, gray.cols - 1));
  }
  return sum / corners.size();
}

}  // namespace

ChessboardDetection DetectChessboard(const cv::Mat& gray, const ChessboardDetectionOptions& options) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  ChessboardDetection detection;
  const cv::Size pattern(options.cols, options.rows);
  const int longer = std::max(gray.cols, gray.rows);
  std::vector<cv::Point2f> coarse;
  double scale = 1.0;
  bool found = false;
  if (options.coarse_max_image_size > 0 && longer > options.coarse_max_image_size) {
    scale = static_cast<double>(options.coarse_max_image_size) / longer;
    cv::Mat small;
    cv::resize(gray, small, cv::Size(), scale, scale, cv::INTER_AREA);
    found = FindCoarse(small, pattern, &coarse);
  }
  if (!found) {
    scale = 1.0;
    found = FindCoarse(gray, pattern, &coarse);
  }
  if (!found) {
    detection.reason = "no " + std::to_string(options.cols) + "x" + std::to_string(options.rows) +
                       " inner-corner chessboard found";
    return detection;
  }
  // Back to full-resolution COLMAP pixels: OpenCV's (0, 0) is the centre of
  // the top-left pixel, also in the downscaled image.
  std::vector<Eigen::Vector2d> start;
  for (const cv::Point2f& p : coarse) start.emplace_back((p.x + 0.5) / scale, (p.y + 0.5) / scale);

  // Canonical order: corner 0's outer diagonal square is black. OpenCV may
  // start at the far corner (the same grid rotated by 180 degrees).
  const int squares = (options.cols + 1) + (options.rows + 1);
  detection.symmetric = squares % 2 == 0;
  const double mid = MeanCornerGray(gray, start);
  if (OuterDiagonalGray(gray, start, options.cols) > mid) std::reverse(start.begin(), start.end());

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
