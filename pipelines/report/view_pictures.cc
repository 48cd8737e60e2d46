#include "pipelines/report/view_pictures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/string_utils.h"
#include "pipelines/report/picture.h"

namespace portcal {
namespace {

// The view's image scaled to `width` px (BGR), or a grey frame of the
// camera's proportions where it cannot be read; `scale` gets image px ->
// drawn px. A reduced decode where the image is much larger than drawn.
cv::Mat ViewImage(const std::filesystem::path& image_root, const std::string& name,
                  const Camera& camera, int width, double* scale, bool* read = nullptr) {
  *scale = static_cast<double>(width) / std::max<uint64_t>(1, camera.width);
  const int height = std::max(1, static_cast<int>(std::lround(camera.height * *scale)));
  cv::Mat image;
  if (!image_root.empty()) {
    const int flags = *scale <= 0.25  ? cv::IMREAD_REDUCED_COLOR_4
                      : *scale <= 0.5 ? cv::IMREAD_REDUCED_COLOR_2
                                      : cv::IMREAD_COLOR;
    image = cv::imread((image_root / name).string(), flags);
  }
  if (read) *read = !image.empty();
  cv::Mat drawn;
  if (image.empty()) {
    drawn = cv::Mat(height, width, CV_8UC3, cv::Scalar(200, 200, 200));
  } else {
    cv::resize(image, drawn, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  }
  return drawn;
}

cv::Point Drawn(const Eigen::Vector2d& pixel, double scale) {
  // COLMAP pixels: the top-left pixel's centre at (0.5, 0.5).
  return cv::Point(static_cast<int>(std::lround((pixel.x() - 0.5) * scale)),
                   static_cast<int>(std::lround((pixel.y() - 0.5) * scale)));
}

// A column of pictures under a title, each with a caption above it.
cv::Mat Stacked(const std::vector<std::pair<std::string, cv::Mat>>& parts,
                const std::string& title) {
  int width = 640, height = kTitleHeight;
  for (const auto& [caption, part] : parts) {
    width = std::max(width, part.cols + 20);
    height += 26 + part.rows + 10;
  }
  cv::Mat canvas = TitledCanvas(width, height, title);
  int y = kTitleHeight;
  for (const auto& [caption, part] : parts) {
    DrawLabel(&canvas, caption, cv::Point(10, y + 18), 0.5);
    part.copyTo(canvas(cv::Rect(10, y + 26, part.cols, part.rows)));
    y += 26 + part.rows + 10;
  }
  return canvas;
}

}  // namespace

cv::Mat WorstViewsPicture(const ViewsAtPoses& views, const std::filesystem::path& image_root,
                          int count) {
  const Camera& camera = views.camera.camera;
  const std::vector<PointResidual> residuals = ResidualsAtPoses(views);
  std::vector<double> lengths;
  std::map<int, std::vector<const PointResidual*>> by_view;
  for (const PointResidual& r : residuals) {
    if (r.dropped) continue;
    by_view[r.view].push_back(&r);
    lengths.push_back(r.residual.norm());
  }
  std::vector<int> order;
  for (const auto& [view, points] : by_view) order.push_back(view);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return views.calibrated[static_cast<size_t>(a)].rms_px >
           views.calibrated[static_cast<size_t>(b)].rms_px;
  });
  order.resize(std::min<size_t>(order.size(), static_cast<size_t>(std::max(0, count))));
  double p95 = 0;
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(),
                     lengths.begin() + static_cast<long>(0.95 * (lengths.size() - 1)),
                     lengths.end());
    p95 = lengths[static_cast<size_t>(0.95 * (lengths.size() - 1))];
  }
  const double magnify = p95 > 0 ? 20.0 / p95 : 1.0;
  std::vector<std::pair<std::string, cv::Mat>> parts;
  for (const int v : order) {
    double scale = 1;
    cv::Mat drawn = ViewImage(image_root, views.calibrated[static_cast<size_t>(v)].image_name,
                              camera, 720, &scale);
    for (const PointResidual* r : by_view[v]) {
      const cv::Point at = Drawn(r->observed, scale);
      cv::circle(drawn, at, 3, cv::Scalar(0, 200, 0), 1, cv::LINE_AA);
      cv::arrowedLine(drawn, at,
                      at + cv::Point(static_cast<int>(std::lround(r->residual.x() * magnify)),
                                     static_cast<int>(std::lround(r->residual.y() * magnify))),
                      cv::Scalar(30, 30, 230), 2, cv::LINE_AA, 0, 0.25);
    }
    parts.push_back({views.calibrated[static_cast<size_t>(v)].image_name + ": RMS " +
                         FormatFixed(views.calibrated[static_cast<size_t>(v)].rms_px, 3) + " px",
                     drawn});
  }
  return Stacked(parts, "The " + std::to_string(parts.size()) + " worst views: residuals x" +
                            FormatFixed(magnify, 0) + " (red), corners (green)");
}

cv::Mat ThumbnailsPicture(const ViewsAtPoses& views, const std::filesystem::path& image_root) {
  if (image_root.empty()) return cv::Mat();
  constexpr int kColumns = 6, kWidth = 200, kMaxViews = 48;
  std::map<std::string, const CalibrationView*> by_name;
  for (const CalibrationView& view : views.views) by_name[view.image_name] = &view;
  const Camera& camera = views.camera.camera;
  const int count = std::min<int>(kMaxViews, static_cast<int>(views.calibrated.size()));
  const int thumb_h = std::max(
      1,
      static_cast<int>(std::lround(camera.height * kWidth / std::max<uint64_t>(1, camera.width))));
  const int rows = (count + kColumns - 1) / kColumns;
  cv::Mat canvas = TitledCanvas(
      kColumns * (kWidth + 8) + 8, kTitleHeight + rows * (thumb_h + 24),
      "The views (" + std::to_string(views.calibrated.size()) + ") with their corners");
  int read = 0;
  for (int i = 0; i < count; ++i) {
    const CalibratedView& calibrated = views.calibrated[static_cast<size_t>(i)];
    double scale = 1;
    bool image_read = false;
    cv::Mat thumb =
        ViewImage(image_root, calibrated.image_name, camera, kWidth, &scale, &image_read);
    read += image_read;
    const auto it = by_name.find(calibrated.image_name);
    if (it != by_name.end()) {
      for (const Eigen::Vector2d& pixel : it->second->pixels) {
        cv::circle(thumb, Drawn(pixel, scale), 2,
                   calibrated.dropped ? cv::Scalar(128, 128, 128) : cv::Scalar(0, 200, 0),
                   cv::FILLED);
      }
    }
    const int x = 8 + (i % kColumns) * (kWidth + 8),
              y = kTitleHeight + (i / kColumns) * (thumb_h + 24);
    thumb.copyTo(canvas(cv::Rect(x, y, thumb.cols, thumb.rows)));
    std::string name = calibrated.image_name.substr(calibrated.image_name.find_last_of('/') + 1);
    if (name.size() > 24) name = name.substr(0, 22) + "..";
    DrawLabel(&canvas, name + (calibrated.dropped ? " (dropped)" : ""),
              cv::Point(x, y + thumb_h + 16), 0.4);
  }
  return read > 0 ? canvas : cv::Mat();
}

}  // namespace portcal
