#include "pipelines/synthetic/textures.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "colmap_ext/util/error.h"

namespace portcal {

ChessboardTexture::ChessboardTexture(int inner_cols, int inner_rows, double square, double margin,
                                     const PrintLevels& levels)
    : cols_(inner_cols),
      rows_(inner_rows),
      square_(square),
      margin_(margin),
      white_(static_cast<float>(levels.white)),
      black_(static_cast<float>(levels.black)) {}

Eigen::Vector4d ChessboardTexture::Extent() const {
  return {-square_ - margin_, cols_ * square_ + margin_, -square_ - margin_,
          rows_ * square_ + margin_};
}

bool ChessboardTexture::Gray(double x, double y, float* gray) const {
  const Eigen::Vector4d e = Extent();
  if (x < e[0] || x > e[1] || y < e[2] || y > e[3]) return false;
  if (x < -square_ || x >= cols_ * square_ || y < -square_ || y >= rows_ * square_) {
    *gray = white_;
    return true;
  }
  const int i = static_cast<int>(std::floor(x / square_)) + 1;
  const int j = static_cast<int>(std::floor(y / square_)) + 1;
  *gray = (i + j) % 2 == 0 ? black_ : white_;
  return true;
}

namespace {

Eigen::Vector4d BoundingBox(const std::array<Eigen::Vector2d, 4>& corners) {
  Eigen::Vector4d box(1e300, -1e300, 1e300, -1e300);
  for (const auto& c : corners) {
    box[0] = std::min(box[0], c.x());
    box[1] = std::max(box[1], c.x());
    box[2] = std::min(box[2], c.y());
    box[3] = std::max(box[3], c.y());
  }
  return box;
}

// Buckets boxes into a uniform grid of `cell` over `extent`.
void BuildGrid(const std::vector<Eigen::Vector4d>& boxes, const Eigen::Vector4d& extent,
               double cell, int* cols, int* rows, std::vector<std::vector<int>>* grid) {
  *cols = std::max(1, static_cast<int>(std::ceil((extent[1] - extent[0]) / cell)));
  *rows = std::max(1, static_cast<int>(std::ceil((extent[3] - extent[2]) / cell)));
  grid->assign(static_cast<size_t>(*cols) * *rows, {});
  for (size_t i = 0; i < boxes.size(); ++i) {
    const int c0 = std::max(0, static_cast<int>((boxes[i][0] - extent[0]) / cell));
    const int c1 = std::min(*cols - 1, static_cast<int>((boxes[i][1] - extent[0]) / cell));
    const int r0 = std::max(0, static_cast<int>((boxes[i][2] - extent[2]) / cell));
    const int r1 = std::min(*rows - 1, static_cast<int>((boxes[i][3] - extent[2]) / cell));
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) (*grid)[r * *cols + c].push_back(static_cast<int>(i));
    }
  }
}

const std::vector<int>* Cell(const std::vector<std::vector<int>>& grid, int cols, int rows,
                             const Eigen::Vector4d& extent, double cell, double x, double y) {
  const int c = static_cast<int>((x - extent[0]) / cell);
  const int r = static_cast<int>((y - extent[2]) / cell);
  if (c < 0 || r < 0 || c >= cols || r >= rows) return nullptr;
  return &grid[r * cols + c];
}

}  // namespace

MarkerBoardTexture::MarkerBoardTexture(std::vector<PlacedMarker> markers,
                                       const Eigen::Vector4d& extent, const PrintLevels& levels)
    : markers_(std::move(markers)),
      extent_(extent),
      white_(static_cast<float>(levels.white)),
      black_(static_cast<float>(levels.black)) {
  std::vector<Eigen::Vector4d> boxes;
  double side = 0;
  for (const PlacedMarker& m : markers_) {
    boxes.push_back(BoundingBox(m.corners));
    side = std::max(side, (m.corners[1] - m.corners[0]).norm());
  }
  cell_ = side > 0 ? side : 1.0;
  BuildGrid(boxes, extent_, cell_, &grid_cols_, &grid_rows_, &grid_);
}

void MarkerBoardTexture::SetSquares(int squares_x, int squares_y, double square) {
  squares_x_ = squares_x;
  squares_y_ = squares_y;
  square_ = square;
  square_has_marker_.assign(static_cast<size_t>(squares_x) * squares_y, 0);
  for (const PlacedMarker& m : markers_) {
    const Eigen::Vector2d center =
        0.25 * (m.corners[0] + m.corners[1] + m.corners[2] + m.corners[3]);
    const int i = static_cast<int>(std::floor(center.x() / square));
    const int j = static_cast<int>(std::floor(center.y() / square));
    if (i >= 0 && j >= 0 && i < squares_x && j < squares_y)
      square_has_marker_[j * squares_x + i] = 1;
  }
}

bool MarkerBoardTexture::MarkerGray(const PlacedMarker& m, double x, double y, float* gray) const {
  const Eigen::Vector2d p(x, y);
  const Eigen::Vector2d u_axis = m.corners[1] - m.corners[0];
  const Eigen::Vector2d v_axis = m.corners[3] - m.corners[0];
  const double u = (p - m.corners[0]).dot(u_axis) / u_axis.squaredNorm();
  const double v = (p - m.corners[0]).dot(v_axis) / v_axis.squaredNorm();
  if (u < 0 || u >= 1 || v < 0 || v >= 1) return false;
  const int n = m.modules_per_side;
  const int col = std::min(n - 1, static_cast<int>(u * n));
  const int row = std::min(n - 1, static_cast<int>(v * n));
  *gray = m.modules[row * n + col] ? white_ : black_;
  return true;
}

bool MarkerBoardTexture::Gray(double x, double y, float* gray) const {
  if (x < extent_[0] || x > extent_[1] || y < extent_[2] || y > extent_[3]) return false;
  if (const std::vector<int>* cell = Cell(grid_, grid_cols_, grid_rows_, extent_, cell_, x, y)) {
    for (const int i : *cell) {
      if (MarkerGray(markers_[i], x, y, gray)) return true;
    }
  }
  *gray = white_;
  if (squares_x_ > 0 && x >= 0 && y >= 0 && x < squares_x_ * square_ && y < squares_y_ * square_) {
    const int i = static_cast<int>(x / square_), j = static_cast<int>(y / square_);
    if (!square_has_marker_[j * squares_x_ + i]) *gray = black_;
  }
  return true;
}

DotsFaceTexture::DotsFaceTexture(std::vector<Dot> dots, PlacedMarker marker, double quiet_zone,
                                 const Eigen::Vector4d& extent, const PrintLevels& levels)
    : dots_(std::move(dots)),
      marker_({marker}, extent, levels),
      extent_(extent),
      white_(static_cast<float>(levels.white)) {
  const Eigen::Vector4d box = BoundingBox(marker.corners);
  marker_zone_ = box + Eigen::Vector4d(-quiet_zone, quiet_zone, -quiet_zone, quiet_zone);
  std::vector<Eigen::Vector4d> boxes;
  double max_radius = 1e-3;
  for (const Dot& d : dots_) {
    boxes.emplace_back(d.x - d.radius, d.x + d.radius, d.y - d.radius, d.y + d.radius);
    max_radius = std::max(max_radius, d.radius);
  }
  cell_ = 2 * max_radius;
  BuildGrid(boxes, extent_, cell_, &grid_cols_, &grid_rows_, &grid_);
}

bool DotsFaceTexture::Gray(double x, double y, float* gray) const {
  if (x < extent_[0] || x > extent_[1] || y < extent_[2] || y > extent_[3]) return false;
  if (x >= marker_zone_[0] && x <= marker_zone_[1] && y >= marker_zone_[2] &&
      y <= marker_zone_[3]) {
    return marker_.Gray(x, y, gray);  // white outside the marker itself
  }
  *gray = white_;
  if (const std::vector<int>* cell = Cell(grid_, grid_cols_, grid_rows_, extent_, cell_, x, y)) {
    for (const int i : *cell) {
      const Dot& d = dots_[i];
      if ((x - d.x) * (x - d.x) + (y - d.y) * (y - d.y) <= d.radius * d.radius) {
        *gray = d.gray;
        break;
      }
    }
  }
  return true;
}

RasterTexture::RasterTexture(cv::Mat image, double x0, double y0, double texel)
    : image_(std::move(image)), x0_(x0), y0_(y0), texel_(texel) {
  PORTCAL_CHECK(image_.type() == CV_8UC1 && texel_ > 0);
}

Eigen::Vector4d RasterTexture::Extent() const {
  return {x0_, x0_ + image_.cols * texel_, y0_, y0_ + image_.rows * texel_};
}

bool RasterTexture::Gray(double x, double y, float* gray) const {
  const double u = (x - x0_) / texel_ - 0.5, v = (y - y0_) / texel_ - 0.5;
  if (!(u >= -0.5 && v >= -0.5 && u <= image_.cols - 0.5 && v <= image_.rows - 0.5)) return false;
  const int c0 = std::clamp(static_cast<int>(std::floor(u)), 0, image_.cols - 1);
  const int r0 = std::clamp(static_cast<int>(std::floor(v)), 0, image_.rows - 1);
  const int c1 = std::min(c0 + 1, image_.cols - 1), r1 = std::min(r0 + 1, image_.rows - 1);
  const double a = std::clamp(u - c0, 0.0, 1.0), b = std::clamp(v - r0, 0.0, 1.0);
  const auto at = [&](int r, int c) { return static_cast<double>(image_.at<uint8_t>(r, c)); };
  *gray = static_cast<float>((1 - b) * ((1 - a) * at(r0, c0) + a * at(r0, c1)) +
                             b * ((1 - a) * at(r1, c0) + a * at(r1, c1)));
  return true;
}

cv::Mat RandomShapesRaster(int cols, int rows, int num_shapes, uint64_t seed, int min_size_px,
                           int max_size_px) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> gray(15, 240), x(0, cols - 1), y(0, rows - 1),
      size(min_size_px, max_size_px), kind(0, 2);
  std::uniform_real_distribution<double> angle(0, 180);
  cv::Mat image(rows, cols, CV_8UC1, cv::Scalar(110));
  for (int i = 0; i < num_shapes; ++i) {
    // y before x, one per statement (see SampleTargetView: the arguments'
    // order is the compiler's; this is gcc's).
    const int center_y = y(rng);
    const int center_x = x(rng);
    const cv::Point center(center_x, center_y);
    const int s = size(rng), g = gray(rng), k = kind(rng);
    const double a = angle(rng);
    if (k == 0) {
      cv::circle(image, center, s, cv::Scalar(g), cv::FILLED, cv::LINE_8);
    } else if (k == 1) {
      cv::ellipse(image, center, cv::Size(s, std::max(1, s / 3)), a, 0, 360, cv::Scalar(g),
                  cv::FILLED, cv::LINE_8);
    } else {
      const cv::RotatedRect rect(center, cv::Size2f(s, 0.6f * s), a);
      cv::Point2f p[4];
      rect.points(p);
      std::vector<cv::Point> poly(p, p + 4);
      cv::fillConvexPoly(image, poly, cv::Scalar(g), cv::LINE_8);
    }
  }
  return image;
}

}  // namespace portcal
