// The pictures of the reports, drawn with OpenCV's drawing (lines, circles,
// text, colour maps) and encoded as PNG: a heat map over the image with its
// colour bar, a bar chart, and a canvas in metres for plans seen from above.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace portcal {

// Text at a readable size on a white canvas (OpenCV's Hershey simplex).
void DrawLabel(cv::Mat* canvas, const std::string& text, cv::Point origin, double scale = 0.5,
               cv::Scalar colour = cv::Scalar(0, 0, 0));

// A white canvas of `width` x `height` with `title` written at its top;
// the drawing starts kTitleHeight below.
constexpr int kTitleHeight = 40;
cv::Mat TitledCanvas(int width, int height, const std::string& title);

// A distinct colour for item `index` of `count` (hues around the circle).
cv::Scalar DistinctColour(int index, int count);

struct HeatMapStyle {
  std::string title;
  std::string unit;                    // of the colour bar, e.g. "px"
  std::vector<double> contour_levels;  // white iso-lines
  double max_value = 0;                // top of the colour bar; 0: the grid's maximum
};

// How much an image is scaled to be drawn: 640-960 px wide, so that a small
// image's title fits and a large one fits a page.
double DrawingScale(double image_width);

// A grid of values over the image (rows x cols evenly spread; negative: no
// value, drawn grey) as a colour map DrawingScale() of the image, with a
// colour bar.
cv::Mat HeatMapPicture(const Eigen::MatrixXd& grid, int image_width, int image_height,
                       const HeatMapStyle& style);

// Bars of `values` in `colours`, labelled every few bars by `labels`, with a
// dashed horizontal line at `reference` (<= 0: none) named `reference_name`.
cv::Mat BarChartPicture(const std::vector<double>& values, const std::vector<cv::Scalar>& colours,
                        const std::vector<std::string>& labels, const std::string& title,
                        const std::string& unit, double reference,
                        const std::string& reference_name);

// A plan in metres on a canvas: x to the right, `up` (the plan's second
// coordinate) drawn upwards, equal scale, the extent of the points given
// with a margin, and a scale bar.
class PlanCanvas {
 public:
  PlanCanvas(const std::vector<Eigen::Vector2d>& extent_points, int width, int height,
             const std::string& title);
  cv::Point operator()(const Eigen::Vector2d& plan) const;
  double PixelsPerMetre() const { return scale_; }
  cv::Mat& image() { return image_; }
  void DrawScaleBar(const std::string& axes);  // e.g. "x right, z forward"

 private:
  cv::Mat image_;
  Eigen::Vector2d centre_;
  double scale_ = 1;
};

// PNG bytes of `picture`, written atomically to `path`. Throws InputError.
void WritePng(const cv::Mat& picture, const std::filesystem::path& path);

}  // namespace portcal
