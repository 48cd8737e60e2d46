#include "pipelines/report/lens_pictures.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/report/picture.h"

namespace portcal {
namespace {

double NormalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

}  // namespace

cv::Mat ResidualHistogramPicture(const std::vector<Eigen::Vector2d>& residuals, double sigma_px,
                                 const std::string& title) {
  constexpr int kBins = 48;
  constexpr double kRangeSigmas = 4;
  const double sigma = sigma_px > 0 ? sigma_px : 1;
  std::vector<double> counts(kBins, 0);
  int beyond_3_sigma = 0, values = 0;
  for (const Eigen::Vector2d& r : residuals) {
    for (const double v : {r.x(), r.y()}) {
      if (!std::isfinite(v)) continue;
      ++values;
      beyond_3_sigma += std::abs(v) > 3 * sigma;
      // The outer bins take what lies beyond the range.
      const int bin =
          static_cast<int>(std::floor((v / sigma + kRangeSigmas) / (2 * kRangeSigmas) * kBins));
      counts[static_cast<size_t>(std::clamp(bin, 0, kBins - 1))] += 1;
    }
  }
  std::vector<double> expected(kBins);
  for (int b = 0; b < kBins; ++b) {
    const double lo = -kRangeSigmas + 2 * kRangeSigmas * b / kBins,
                 hi = lo + 2 * kRangeSigmas / kBins;
    expected[static_cast<size_t>(b)] =
        values * (NormalCdf(b == kBins - 1 ? 1e9 : hi) - NormalCdf(b == 0 ? -1e9 : lo));
  }
  const std::string heading = title + ": " + std::to_string(values) + " values, sigma " +
                              FormatFixed(sigma, 3) + " px; beyond 3 sigma " +
                              FormatFixed(100.0 * beyond_3_sigma / std::max(1, values), 2) +
                              " % (Gaussian 0.27 %)";
  const int left = 50, bottom = 50, plot_w = 720, plot_h = 260;
  // Hershey simplex at the title's scale: about 11 px a character.
  cv::Mat canvas =
      TitledCanvas(std::max(left + plot_w + 30, 11 * static_cast<int>(heading.size()) + 16),
                   kTitleHeight + plot_h + bottom, heading);
  const double top = std::max(*std::max_element(counts.begin(), counts.end()),
                              *std::max_element(expected.begin(), expected.end()));
  const int base = kTitleHeight + plot_h;
  const double bin_w = static_cast<double>(plot_w) / kBins;
  const auto y_of = [&](double count) {
    return base - static_cast<int>(plot_h * 0.95 * count / std::max(1.0, top));
  };
  for (int b = 0; b < kBins; ++b) {
    cv::rectangle(
        canvas,
        cv::Point(left + static_cast<int>(b * bin_w) + 1, y_of(counts[static_cast<size_t>(b)])),
        cv::Point(left + static_cast<int>((b + 1) * bin_w) - 1, base), cv::Scalar(160, 110, 40),
        cv::FILLED);
  }
  for (int b = 0; b + 1 < kBins; ++b) {  // the Gaussian through the bins' centres
    cv::line(canvas,
             cv::Point(left + static_cast<int>((b + 0.5) * bin_w),
                       y_of(expected[static_cast<size_t>(b)])),
             cv::Point(left + static_cast<int>((b + 1.5) * bin_w),
                       y_of(expected[static_cast<size_t>(b + 1)])),
             cv::Scalar(40, 40, 220), 2, cv::LINE_AA);
  }
  cv::line(canvas, cv::Point(left, base), cv::Point(left + plot_w, base), cv::Scalar(0, 0, 0), 1);
  for (int s = -4; s <= 4; ++s) {
    const int x = left + static_cast<int>((s + kRangeSigmas) / (2 * kRangeSigmas) * plot_w);
    cv::line(canvas, cv::Point(x, base), cv::Point(x, base + 5), cv::Scalar(0, 0, 0), 1);
    DrawLabel(&canvas, (s > 0 ? "+" : "") + std::to_string(s) + "s", cv::Point(x - 12, base + 22),
              0.45);
  }
  DrawLabel(&canvas, "residual x and y (s = sigma); red: the Gaussian; outer bars: beyond 4 sigma",
            cv::Point(left, base + 44), 0.45);
  return canvas;
}

cv::Mat DistortionPicture(const Camera& camera, const std::vector<Eigen::Vector2d>& observed) {
  const std::vector<int> focal = CameraModelFocalLengthIdxs(camera.model_id);
  const double fx = camera.params[static_cast<size_t>(focal[0])];
  const double fy = camera.params[static_cast<size_t>(focal.size() > 1 ? focal[1] : focal[0])];
  const double cx = camera.PrincipalPointX(), cy = camera.PrincipalPointY();
  const int cols = 48,
            rows = std::max(2, static_cast<int>(std::lround(48.0 * camera.height / camera.width)));
  Eigen::MatrixXd grid(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector2d pixel((c + 0.5) * camera.width / cols,
                                  (r + 0.5) * camera.height / rows);
      const std::optional<Eigen::Vector3d> ray = camera.CamFromImg(pixel);
      grid(r, c) =
          ray && ray->z() > 0
              ? (Eigen::Vector2d(fx * ray->x() / ray->z() + cx, fy * ray->y() / ray->z() + cy) -
                 pixel)
                    .norm()
              : -1;
    }
  }
  HeatMapStyle style;
  style.unit = "px";
  style.contour_levels = {1, 10, 100};
  style.title = "Distortion |lens - pinhole|, max " + FormatFixed(grid.maxCoeff(), 1) + " px";
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  cv::Mat picture = HeatMapPicture(grid, width, height, style);
  std::vector<cv::Point2f> points;
  for (const Eigen::Vector2d& p : observed) {
    if (std::isfinite(p.x()) && std::isfinite(p.y()))
      points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  if (points.size() >= 3) {
    std::vector<cv::Point2f> hull;
    cv::convexHull(points, hull);
    const double scale = DrawingScale(static_cast<double>(camera.width));
    std::vector<cv::Point> drawn;
    for (const cv::Point2f& p : hull) {
      drawn.emplace_back(static_cast<int>(std::lround(p.x * scale)),
                         kTitleHeight + static_cast<int>(std::lround(p.y * scale)));
    }
    cv::polylines(picture, std::vector<std::vector<cv::Point>>{drawn}, true,
                  cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  }
  return picture;
}

cv::Mat CorrelationPicture(const Eigen::MatrixXd& covariance, const std::vector<std::string>& names,
                           const std::string& title) {
  std::vector<int> kept;
  for (int i = 0; i < covariance.rows() && i < static_cast<int>(names.size()); ++i) {
    if (covariance(i, i) > 0 && std::isfinite(covariance(i, i))) kept.push_back(i);
  }
  if (kept.size() < 2) return cv::Mat();
  const int n = static_cast<int>(kept.size()), cell = std::clamp(560 / n, 40, 80), left = 110;
  cv::Mat canvas =
      TitledCanvas(std::max(left + n * cell + 20, 640), kTitleHeight + 30 + n * cell + 20, title);
  const int top = kTitleHeight + 30;
  for (int a = 0; a < n; ++a) {
    DrawLabel(&canvas, names[static_cast<size_t>(kept[a])],
              cv::Point(10, top + a * cell + cell / 2 + 5), 0.5);
    DrawLabel(&canvas, names[static_cast<size_t>(kept[a])], cv::Point(left + a * cell + 4, top - 8),
              0.45);
    for (int b = 0; b < n; ++b) {
      const double rho = covariance(kept[a], kept[b]) /
                         std::sqrt(covariance(kept[a], kept[a]) * covariance(kept[b], kept[b]));
      const double m = std::clamp(std::abs(rho), 0.0, 1.0);
      // White at 0, towards red (positive) or blue (negative); BGR.
      const cv::Scalar colour = rho >= 0 ? cv::Scalar(255 * (1 - m), 255 * (1 - m), 255)
                                         : cv::Scalar(255, 255 * (1 - m), 255 * (1 - m));
      const cv::Rect box(left + b * cell, top + a * cell, cell - 1, cell - 1);
      cv::rectangle(canvas, box, colour, cv::FILLED);
      DrawLabel(&canvas, FormatFixed(rho, 2), cv::Point(box.x + 3, box.y + cell / 2 + 5), 0.4,
                m > 0.7 ? cv::Scalar(255, 255, 255) : cv::Scalar(0, 0, 0));
    }
  }
  return canvas;
}

}  // namespace portcal
