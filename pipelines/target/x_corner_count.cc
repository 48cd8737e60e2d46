#include "pipelines/target/x_corner_count.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "colmap_ext/util/error.h"

namespace portcal {

void XCornerCountOptions::Check() const {
  if (ring_radius_px < 2) throw OptionError("ring_radius_px", ring_radius_px, ">= 2");
  if (!(min_normalised_response > 0 && min_normalised_response < 1)) {
    throw OptionError("min_normalised_response", min_normalised_response, "(0, 1)");
  }
  if (!(min_response >= 0)) throw OptionError("min_response", min_response, ">= 0");
  if (!(spacing_tolerance > 0 && spacing_tolerance < 1)) {
    throw OptionError("spacing_tolerance", spacing_tolerance, "(0, 1)");
  }
}

namespace {

constexpr int kMaxJunctions = 5000;

// 255 where the response passes the thresholds, 0 elsewhere (CV_8U), the
// ring's 16 samples turned by `phase` of their spacing. Whole-image
// arithmetic on shifted views (vectorised by OpenCV); the spread, needed
// only where the response is high, per pixel.
cv::Mat JunctionMask(const cv::Mat& gray, const XCornerCountOptions& options, double phase) {
  const int r = options.ring_radius_px;
  // Sampled from the image averaged over 3 x 3 pixels: sensor noise alone
  // makes junction-like rings often enough otherwise.
  cv::Mat smooth;
  cv::blur(gray, smooth, cv::Size(3, 3));
  cv::Mat padded;
  cv::copyMakeBorder(smooth, padded, r, r, r, r, cv::BORDER_REPLICATE);
  cv::Mat padded16;
  padded.convertTo(padded16, CV_16S);
  std::array<cv::Mat, 16>
      ring;  // views of the samples (16-bit: same-type arithmetic is vectorised)
  for (int k = 0; k < 16; ++k) {
    const int dx = static_cast<int>(std::lround(r * std::cos(2 * M_PI * (k + phase) / 16)));
    const int dy = static_cast<int>(std::lround(r * std::sin(2 * M_PI * (k + phase) / 16)));
    ring[k] = padded16(cv::Rect(r + dx, r + dy, gray.cols, gray.rows));
  }
  // ChESS: opposite samples alike, a quarter turn apart unlike; less
  // opposite samples unlike (an edge); less the ring's mean against the
  // centre (a line or a spot), all times 16.
  std::array<cv::Mat, 8> opposite_sum;
  cv::Mat sum(gray.size(), CV_16S, cv::Scalar(0)), value(gray.size(), CV_16S, cv::Scalar(0)),
      difference;
  for (int k = 0; k < 8; ++k) {
    cv::add(ring[k], ring[k + 8], opposite_sum[k]);
    cv::add(sum, opposite_sum[k], sum);
    cv::absdiff(ring[k], ring[k + 8], difference);
    cv::subtract(value, difference, value);
  }
  for (int k = 0; k < 4; ++k) {
    cv::absdiff(opposite_sum[k], opposite_sum[k + 4], difference);
    cv::add(value, difference, value);
  }
  cv::Mat centre16 = padded16(cv::Rect(r, r, gray.cols, gray.rows)) * 16;
  cv::absdiff(sum, centre16, difference);
  cv::subtract(value, difference, value);

  cv::Mat mask(gray.size(), CV_8U, cv::Scalar(0));
  const int min_response = static_cast<int>(std::ceil(options.min_response));
  for (int y = 0; y < gray.rows; ++y) {
    const int16_t* v = value.ptr<int16_t>(y);
    const int16_t* s = sum.ptr<int16_t>(y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    std::array<const int16_t*, 16> rows;
    for (int k = 0; k < 16; ++k) rows[k] = ring[k].ptr<int16_t>(y);
    for (int x = 0; x < gray.cols; ++x) {
      if (v[x] < min_response) continue;
      // The ring's spread about its mean, 16 times over.
      int spread16 = 0;
      for (int k = 0; k < 16; ++k) spread16 += std::abs(16 * rows[k][x] - s[x]);
      if (16.0 * v[x] >= options.min_normalised_response * (spread16 + 128)) out[x] = 255;
    }
  }
  return mask;
}

// Junctions where two grid lines cross: among its 8 nearest junctions, two
// pairs on opposite sides at about equal distances, the pairs' lines at
// least ~30 degrees apart. All but the junctions on a board's outer rows
// and columns are such; scattered junction-like spots in a textured scene
// rarely are (0 to 2 on 9 textured renders without a chessboard, where a
// 10 x 7 board has 40).
int CountGridJunctions(const std::vector<cv::Point2d>& junctions, double tolerance) {
  constexpr int kNeighbours = 8;
  const int n = static_cast<int>(junctions.size());
  int count = 0;
  std::vector<std::pair<double, int>> distances(n);
  for (int b = 0; b < n; ++b) {
    for (int i = 0; i < n; ++i) {
      const cv::Point2d d = junctions[i] - junctions[b];
      distances[i] = {i == b ? 1e300 : d.dot(d), i};
    }
    const int k = std::min(kNeighbours, n - 1);
    std::partial_sort(distances.begin(), distances.begin() + k, distances.end());
    std::vector<double> lines;  // directions (radians mod pi) of opposite pairs
    for (int i = 0; i < k; ++i) {
      const cv::Point2d u = junctions[distances[i].second] - junctions[b];
      const double length = std::sqrt(distances[i].first);
      for (int j = i + 1; j < k; ++j) {
        const cv::Point2d v = junctions[distances[j].second] - junctions[b];
        const cv::Point2d miss = u + v;
        if (std::abs(std::sqrt(distances[j].first) - length) > tolerance * length ||
            std::hypot(miss.x, miss.y) > tolerance * length) {
          continue;
        }
        lines.push_back(std::fmod(std::atan2(u.y, u.x) + M_PI, M_PI));
      }
    }
    bool crossing = false;
    for (size_t i = 0; i < lines.size() && !crossing; ++i) {
      for (size_t j = i + 1; j < lines.size() && !crossing; ++j) {
        const double angle = std::abs(lines[i] - lines[j]);
        crossing = std::min(angle, M_PI - angle) > 0.5;
      }
    }
    count += crossing;
  }
  return count;
}

// Grid junctions at this scale, with the ring as sampled and turned by half
// a step: samples on a board's edges (a board square to the image, its
// junctions between pixels) make one of the two blind there.
int CountAtScale(const cv::Mat& gray, const XCornerCountOptions& options, int enough) {
  int best = 0;
  for (const double phase : {0.0, 0.5}) {
    if (best >= enough) break;
    cv::Mat labels, stats, centroids;
    const int num_labels = cv::connectedComponentsWithStats(JunctionMask(gray, options, phase),
                                                            labels, stats, centroids, 8, CV_32S);
    // More spots than a textured scene at this size gives (~500) would
    // make the search slow; so many cannot be judged, they pass.
    if (num_labels > kMaxJunctions) return std::numeric_limits<int>::max();
    std::vector<cv::Point2d> junctions;
    for (int i = 1; i < num_labels; ++i) {
      junctions.emplace_back(centroids.at<double>(i, 0), centroids.at<double>(i, 1));
    }
    best = std::max(best, CountGridJunctions(junctions, options.spacing_tolerance));
  }
  return best;
}

}  // namespace

int CountXCorners(const cv::Mat& gray, const XCornerCountOptions& options, int enough) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  if (gray.cols < 4 * options.ring_radius_px || gray.rows < 4 * options.ring_radius_px) return 0;
  // The half scale first: a quarter of the work, and enough for most views.
  cv::Mat half;
  cv::resize(gray, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  const int at_half = CountAtScale(half, options, enough);
  if (at_half >= enough) return at_half;
  return std::max(at_half, CountAtScale(gray, options, enough));
}

}  // namespace portcal
