// The coarse level detectors search first: the image halved until it fits.
#pragma once

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace portcal {

// The image halved (a power of two: INTER_AREA is then a plain box average,
// several times faster than by any other factor) until its longer side is
// at most `max_size`, with the factor; the image itself when it fits or
// `max_size` is 0. A point p of the level (OpenCV pixels, (0, 0) the centre
// of the top-left pixel) is (p + 0.5) / factor - 0.5 in the image.
inline std::pair<double, cv::Mat> CoarseLevel(const cv::Mat& gray, int max_size) {
  const int longer = std::max(gray.cols, gray.rows);
  if (max_size <= 0 || longer <= max_size) return {1.0, gray};
  double factor = 1.0;
  while (longer * factor > max_size) factor /= 2;
  cv::Mat small;
  cv::resize(gray, small, cv::Size(), factor, factor, cv::INTER_AREA);
  return {factor, small};
}

}  // namespace portcal
