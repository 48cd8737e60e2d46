#include "pipelines/report/picture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

namespace {

// OpenCV's viridis, looked up once.
cv::Vec3b Viridis(double fraction) {
  static const cv::Mat table = [] {
    cv::Mat ramp(1, 256, CV_8U), colours;
    for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
    cv::applyColorMap(ramp, colours, cv::COLORMAP_VIRIDIS);
    return colours;
  }();
  return table.at<cv::Vec3b>(0, cv::saturate_cast<uint8_t>(255.0 * std::clamp(fraction, 0.0, 1.0)));
}

// The colour bar right of a map at (x, top), `h` high, 0..max_value.
void DrawColourBar(cv::Mat* canvas, int x, int top, int h, double max_value,
                   const std::string& unit) {
  for (int r = 0; r < h; ++r) {
    cv::line(*canvas, cv::Point(x, top + r), cv::Point(x + 20, top + r),
             cv::Scalar(Viridis(static_cast<double>(h - 1 - r) / std::max(1, h - 1))), 1);
  }
  for (int t = 0; t <= 4; ++t) {
    const int y = top + (h - 1) - (h - 1) * t / 4;
    DrawLabel(canvas, FormatSignificant(max_value * t / 4, 3), cv::Point(x + 24, y + 5), 0.45);
  }
  DrawLabel(canvas, unit, cv::Point(x + 2, top - 6), 0.45);
}

}  // namespace

void DrawLabel(cv::Mat* canvas, const std::string& text, cv::Point origin, double scale,
               cv::Scalar colour) {
  cv::putText(*canvas, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

cv::Mat TitledCanvas(int width, int height, const std::string& title) {
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  DrawLabel(&canvas, title, cv::Point(8, 26), 0.55);
  return canvas;
}

cv::Scalar DistinctColour(int index, int count) {
  cv::Mat hsv(1, 1, CV_8UC3,
              cv::Scalar(static_cast<uint8_t>(180.0 * index / std::max(1, count)), 220, 200));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return cv::Scalar(bgr.at<cv::Vec3b>(0, 0));
}

double DrawingScale(double image_width) {
  return image_width < 640 ? 640.0 / image_width : std::min(1.0, 960.0 / image_width);
}

cv::Mat HeatMapPicture(const Eigen::MatrixXd& grid, int image_width, int image_height,
                       const HeatMapStyle& style) {
  const double scale = DrawingScale(image_width);
  const int w = std::max(1, static_cast<int>(image_width * scale));
  const int h = std::max(1, static_cast<int>(image_height * scale));
  cv::Mat values(static_cast<int>(grid.rows()), static_cast<int>(grid.cols()), CV_32F);
  double max_value = style.max_value;
  for (int r = 0; r < values.rows; ++r) {
    for (int c = 0; c < values.cols; ++c) {
      const double v = std::isfinite(grid(r, c)) ? grid(r, c) : -1.0;
      values.at<float>(r, c) = static_cast<float>(v);
      if (style.max_value <= 0) max_value = std::max(max_value, v);
    }
  }
  if (!(max_value > 0)) max_value = 1;
  cv::Mat dense;
  cv::resize(values, dense, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
  cv::Mat colour(h, w, CV_8UC3);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const float v = dense.at<float>(r, c);
      colour.at<cv::Vec3b>(r, c) = v < 0 ? cv::Vec3b(128, 128, 128) : Viridis(v / max_value);
    }
  }
  for (const double level : style.contour_levels) {
    const cv::Mat above = dense >= level;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(above, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(colour, contours, -1, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  cv::Mat canvas = TitledCanvas(w + 100, h + kTitleHeight + 10, style.title);
  colour.copyTo(canvas(cv::Rect(0, kTitleHeight, w, h)));
  DrawColourBar(&canvas, w + 10, kTitleHeight, h, max_value, style.unit);
  return canvas;
}

cv::Mat BarChartPicture(const std::vector<double>& values, const std::vector<cv::Scalar>& colours,
                        const std::vector<std::string>& labels, const std::string& title,
                        const std::string& unit, double reference,
                        const std::string& reference_name) {
  const int left = 60, bottom = 60, plot_h = 260;
  const int bar_w = std::clamp(800 / std::max<int>(1, static_cast<int>(values.size())), 3, 40);
  const int plot_w = bar_w * static_cast<int>(values.size());
  cv::Mat canvas =
      TitledCanvas(std::max(720, left + plot_w + 20), kTitleHeight + plot_h + bottom, title);
  double max_value = reference;
  for (double v : values) max_value = std::max(max_value, v);
  if (!(max_value > 0)) max_value = 1;
  const int base = kTitleHeight + plot_h;
  const auto y_of = [&](double v) {
    return base - static_cast<int>(plot_h * 0.95 * v / max_value);
  };
  cv::line(canvas, cv::Point(left, base), cv::Point(left + plot_w, base), cv::Scalar(0, 0, 0), 1);
  cv::line(canvas, cv::Point(left, base), cv::Point(left, kTitleHeight), cv::Scalar(0, 0, 0), 1);
  for (int t = 0; t <= 4; ++t) {
    const double v = max_value * 0.95 * t / 4;
    DrawLabel(&canvas, FormatSignificant(v, 3), cv::Point(4, y_of(v) + 5), 0.4);
  }
  DrawLabel(&canvas, unit, cv::Point(4, kTitleHeight - 4), 0.4);
  const int label_every = std::max(1, 40 / bar_w);
  for (size_t i = 0; i < values.size(); ++i) {
    const int x = left + static_cast<int>(i) * bar_w;
    cv::rectangle(canvas, cv::Point(x + 1, y_of(values[i])), cv::Point(x + bar_w - 1, base),
                  colours[i], cv::FILLED);
    if (i % static_cast<size_t>(label_every) == 0 && i < labels.size()) {
      DrawLabel(&canvas, labels[i],
                cv::Point(x, base + 16 + 14 * static_cast<int>((i / label_every) % 2)), 0.35);
    }
  }
  if (reference > 0) {
    for (int x = left; x < left + plot_w; x += 12) {
      cv::line(canvas, cv::Point(x, y_of(reference)),
               cv::Point(std::min(x + 6, left + plot_w), y_of(reference)), cv::Scalar(0, 0, 200),
               1);
    }
    DrawLabel(&canvas, reference_name, cv::Point(left + 4, y_of(reference) - 4), 0.4,
              cv::Scalar(0, 0, 200));
  }
  return canvas;
}

PlanCanvas::PlanCanvas(const std::vector<Eigen::Vector2d>& extent_points, int width, int height,
                       const std::string& title)
    : image_(TitledCanvas(width, height, title)) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(1e300), high = Eigen::Vector2d::Constant(-1e300);
  for (const Eigen::Vector2d& p : extent_points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  if (extent_points.empty()) low = high = Eigen::Vector2d::Zero();
  centre_ = 0.5 * (low + high);
  const Eigen::Vector2d size = (high - low).cwiseMax(1e-9);
  scale_ = std::min((width - 80) / size.x(), (height - kTitleHeight - 80) / size.y());
}

cv::Point PlanCanvas::operator()(const Eigen::Vector2d& plan) const {
  const Eigen::Vector2d d = (plan - centre_) * scale_;
  return cv::Point(static_cast<int>(std::lround(image_.cols / 2.0 + d.x())),
                   static_cast<int>(std::lround((image_.rows + kTitleHeight - 30) / 2.0 - d.y())));
}

void PlanCanvas::DrawScaleBar(const std::string& axes) {
  // A round length about a fifth of the canvas.
  const double target = image_.cols / 5.0 / scale_;
  const double step = std::pow(10.0, std::floor(std::log10(target)));
  const double length = target >= 5 * step ? 5 * step : target >= 2 * step ? 2 * step : step;
  const int y = image_.rows - 14, x = 10, len = static_cast<int>(length * scale_);
  cv::line(image_, cv::Point(x, y), cv::Point(x + len, y), cv::Scalar(0, 0, 0), 2);
  const std::string text = length >= 1 ? FormatSignificant(length, 3) + " m"
                                       : FormatSignificant(length * 1000, 3) + " mm";
  DrawLabel(&image_, text + "   (" + axes + ")", cv::Point(x + len + 8, y + 5), 0.45);
}

void WritePng(const cv::Mat& picture, const std::filesystem::path& path) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", picture, png))
    throw InputError(path.string() + ": PNG encoding failed");
  WriteFileAtomically(path, true, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace portcal
