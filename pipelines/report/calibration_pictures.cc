#include "pipelines/report/calibration_pictures.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/guidance/calibration_unknowns.h"
#include "pipelines/guidance/projection_uncertainty.h"
#include "pipelines/report/picture.h"

namespace portcal {

namespace {

// The image scaled by DrawingScale() under a title.
struct ImageFrame {
  double scale;
  cv::Mat canvas;
  ImageFrame(const Camera& camera, const std::string& title)
      : scale(DrawingScale(static_cast<double>(camera.width))),
        canvas(TitledCanvas(static_cast<int>(camera.width * scale) + 2,
                            static_cast<int>(camera.height * scale) + kTitleHeight + 2, title)) {
    cv::rectangle(canvas,
                  cv::Rect(0, kTitleHeight, canvas.cols - 1, canvas.rows - kTitleHeight - 1),
                  cv::Scalar(0, 0, 0), 1);
  }
  // COLMAP pixel (centre of the top-left pixel at 0.5) -> canvas.
  cv::Point2d operator()(const Eigen::Vector2d& pixel) const {
    return cv::Point2d(pixel.x() * scale, kTitleHeight + pixel.y() * scale);
  }
};

// The views by image name.
std::map<std::string, const CalibrationView*> ByName(const std::vector<CalibrationView>& views) {
  std::map<std::string, const CalibrationView*> by_name;
  for (const CalibrationView& view : views) by_name[view.image_name] = &view;
  return by_name;
}

std::string Fixed(double value, int digits) { return FormatFixed(value, digits); }

}  // namespace

std::vector<PointResidual> ResidualsAtPoses(const ViewsAtPoses& in) {
  const std::map<std::string, const CalibrationView*> by_name = ByName(in.views);
  const Eigen::Vector4d extent = BoardExtent(in.views);
  std::vector<PointResidual> residuals;
  for (size_t v = 0; v < in.calibrated.size(); ++v) {
    const auto it = by_name.find(in.calibrated[v].image_name);
    if (it == by_name.end()) continue;
    const CalibrationView& view = *it->second;
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      Eigen::Vector3d point = view.points_in_target[i];
      if (in.board_warp) point.z() += BoardSag(in.board_warp->data(), BoardWarpUv(point, extent));
      const std::optional<Eigen::Vector2d> predicted =
          in.camera.Project(in.calibrated[v].cam_from_target * point);
      if (!predicted) continue;
      residuals.push_back({view.pixels[i], view.pixels[i] - *predicted, static_cast<int>(v),
                           in.calibrated[v].dropped});
    }
  }
  return residuals;
}

cv::Mat CoveragePicture(const Camera& camera, const std::vector<Eigen::Vector2d>& pixels,
                        const std::string& what) {
  // The verdict's cells (calibration_verdict.h), so that the picture and
  // the verdict count the same empty cells.
  const Eigen::MatrixXd counts =
      CoverageCounts(static_cast<int>(camera.width), static_cast<int>(camera.height), pixels)
          .cast<double>();
  const int rows = static_cast<int>(counts.rows()), cols = static_cast<int>(counts.cols());
  const int empty = static_cast<int>((counts.array() == 0).count());
  HeatMapStyle style;
  style.title = "Coverage: " + std::to_string(pixels.size()) + " " + what + ", " +
                std::to_string(empty) + " of " + std::to_string(rows * cols) + " cells empty";
  style.unit = "per cell";
  cv::Mat picture = HeatMapPicture(counts, static_cast<int>(camera.width),
                                   static_cast<int>(camera.height), style);
  const double scale = DrawingScale(static_cast<double>(camera.width));
  for (const Eigen::Vector2d& p : pixels) {
    cv::circle(picture, cv::Point2d(p.x() * scale, kTitleHeight + p.y() * scale), 1,
               cv::Scalar(255, 255, 255), cv::FILLED);
  }
  return picture;
}

cv::Mat PerViewRmsPicture(const std::vector<CalibratedView>& views, double residual_sigma_px,
                          const std::string& title) {
  std::vector<double> values;
  std::vector<cv::Scalar> colours;
  std::vector<std::string> labels;
  int outliers = 0, dropped = 0;
  for (const CalibratedView& view : views) {
    values.push_back(view.rms_px);
    colours.push_back(view.dropped   ? cv::Scalar(150, 150, 150)
                      : view.outlier ? cv::Scalar(40, 40, 220)
                                     : cv::Scalar(160, 110, 40));
    std::string name = view.image_name.substr(view.image_name.find_last_of('/') + 1);
    labels.push_back(name.substr(0, name.find_last_of('.')));
    outliers += view.outlier && !view.dropped;
    dropped += view.dropped;
  }
  const std::string heading = title + " (" + std::to_string(outliers) + " outliers in red, " +
                              std::to_string(dropped) + " dropped in grey)";
  // RMS of 2-D residuals is sqrt(2) x the per-coordinate sigma.
  return BarChartPicture(values, colours, labels, heading, "px", std::sqrt(2.0) * residual_sigma_px,
                         "sqrt(2) x residual sigma");
}

cv::Mat ResidualVectorsPicture(const Camera& camera, const std::vector<PointResidual>& residuals,
                               int num_views, const std::string& title) {
  std::vector<double> lengths;
  for (const PointResidual& r : residuals) {
    if (!r.dropped) lengths.push_back(r.residual.norm());
  }
  std::sort(lengths.begin(), lengths.end());
  const double p95 = lengths.empty() ? 0 : lengths[lengths.size() * 95 / 100];
  // The 95th percentile drawn as 2.5 % of the image width.
  const double magnify = p95 > 0 ? 0.025 * camera.width / p95 : 1;
  std::ostringstream heading;
  heading << title << ": magnified x" << std::setprecision(3) << magnify << ", p95 "
          << Fixed(p95, 3) << " px";
  ImageFrame frame(camera, heading.str());
  for (const PointResidual& r : residuals) {
    if (r.dropped) continue;
    const cv::Point2d from = frame(r.observed);
    const cv::Point2d to = frame(r.observed + magnify * r.residual);
    cv::arrowedLine(frame.canvas, from, to, DistinctColour(r.view, num_views), 1, cv::LINE_AA, 0,
                    0.2);
  }
  return frame.canvas;
}

ProjectionUncertaintyGrid ProjectionUncertaintyOfViews(const ViewsAtPoses& in,
                                                       bool housing_calibration,
                                                       const std::vector<int>& fixed,
                                                       double pixel_sigma_px) {
  CalibrationUnknowns unknowns{in.camera, housing_calibration, fixed, std::nullopt};
  // Behind a housing the guidance's residual holds the board flat: the
  // warp, when fitted, is taken as known there.
  if (in.board_warp && !in.camera.housing)
    unknowns.board_warp = BoardWarpUnknown{*in.board_warp, BoardExtent(in.views)};
  CalibrationInformation information = CalibrationInformation::Zero(unknowns.NumUnknowns());
  std::vector<double> depths;
  const std::map<std::string, const CalibrationView*> by_name = ByName(in.views);
  for (const CalibratedView& view : in.calibrated) {
    const auto it = by_name.find(view.image_name);
    if (view.dropped || it == by_name.end()) continue;
    information += ViewInformation(unknowns, it->second->points_in_target, view.cam_from_target);
    depths.push_back(view.cam_from_target.translation.z());
  }
  ProjectionUncertaintyOptions options;
  std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2),
                   depths.end());
  options.working_distance_m = depths.empty() ? 1.0 : std::max(0.05, depths[depths.size() / 2]);
  options.grid_cols = 32;
  const Camera& camera = in.camera.camera;
  options.grid_rows =
      std::max(2, static_cast<int>(std::lround(32.0 * camera.height / camera.width)));
  options.pixel_sigma_px = std::max(1e-6, pixel_sigma_px);
  const ProjectionUncertainty uncertainty =
      ProjectionUncertaintyModel(unknowns, options).Evaluate(information);
  ProjectionUncertaintyGrid grid;
  grid.of = housing_calibration ? "housing" : "intrinsics";
  grid.working_distance_m = options.working_distance_m;
  grid.pixel_sigma_px = options.pixel_sigma_px;
  const Eigen::VectorXd xs =
      UncertaintyGridColumns(static_cast<double>(camera.width), options.grid_cols);
  const Eigen::VectorXd ys =
      UncertaintyGridRows(static_cast<double>(camera.height), options.grid_rows);
  grid.x_px.assign(xs.data(), xs.data() + xs.size());
  grid.y_px.assign(ys.data(), ys.data() + ys.size());
  grid.determined = uncertainty.determined;
  grid.at_working_distance_px = uncertainty.map_px;
  grid.at_infinity_px = uncertainty.map_at_infinity_px;
  return grid;
}

cv::Mat UncertaintyPicture(const ProjectionUncertaintyGrid& grid, int width, int height,
                           bool at_infinity) {
  HeatMapStyle style;
  style.unit = "px";
  style.title = "Projection uncertainty of the " + grid.of + " at " +
                (at_infinity ? std::string("infinity") : Fixed(grid.working_distance_m, 2) + " m") +
                ": mean " + Fixed(grid.Mean(at_infinity), 3) + ", max " +
                Fixed(grid.Max(at_infinity), 3) + " px" +
                (grid.determined ? "" : " (UNDETERMINED)");
  style.contour_levels = {grid.Mean(at_infinity)};
  if (!grid.determined) return HeatMapPicture(-Eigen::MatrixXd::Ones(2, 2), width, height, style);
  return HeatMapPicture(at_infinity ? grid.at_infinity_px : grid.at_working_distance_px, width,
                        height, style);
}

}  // namespace portcal
