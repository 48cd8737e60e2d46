#include "pipelines/undistortion/approximation_error.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/util/parallel.h"

namespace portcal {
namespace {

int GridRows(const Camera& pinhole, int grid_cols) {
  return std::max(2, static_cast<int>(std::lround(grid_cols * static_cast<double>(pinhole.height) /
                                                  static_cast<double>(pinhole.width))));
}

DepthError Summarise(double depth, Eigen::MatrixXd grid) {
  DepthError error;
  error.depth = depth;
  std::vector<double> values;
  for (Eigen::Index i = 0; i < grid.size(); ++i) {
    if (grid(i) >= 0) values.push_back(grid(i));
  }
  if (!values.empty()) {
    std::sort(values.begin(), values.end());
    error.max_px = values.back();
    double sum = 0;
    for (const double v : values) sum += v;
    error.mean_px = sum / static_cast<double>(values.size());
    error.p95_px =
        values[static_cast<size_t>(std::floor(0.95 * static_cast<double>(values.size() - 1)))];
  }
  error.grid = std::move(grid);
  return error;
}

// The worst error over `depths` of the pinhole at `design_depth`.
double WorstError(const HousedCamera& camera, double design_depth,
                  const std::vector<double>& depths, const Eigen::Matrix3d& pinhole_from_cam,
                  const FieldOfViewOptions& field_of_view) {
  const VirtualPinhole pinhole =
      FitVirtualPinhole(camera, design_depth, pinhole_from_cam, field_of_view);
  return MeasureApproximationError(pinhole, depths, 24, 1).worst_px;
}

}  // namespace

std::vector<double> SampleDepths(const DepthRange& range, int count, double design_depth) {
  count = std::max(2, count);
  std::vector<double> depths;
  const double log_near = std::log(range.near), log_far = std::log(range.far);
  for (int i = 0; i < count; ++i)
    depths.push_back(std::exp(log_near + (log_far - log_near) * i / (count - 1)));
  depths.front() = range.near;
  depths.back() = range.far;
  const bool inside = design_depth > range.near && design_depth < range.far;
  const bool listed = std::any_of(depths.begin(), depths.end(), [&](double d) {
    return std::abs(d - design_depth) < 1e-9 * design_depth;
  });
  if (inside && !listed) depths.push_back(design_depth);
  std::sort(depths.begin(), depths.end());
  return depths;
}

ApproximationError MeasureApproximationError(const VirtualPinhole& pinhole,
                                             const std::vector<double>& depths, int grid_cols,
                                             int num_threads) {
  const int rows = GridRows(pinhole.pinhole, grid_cols);
  std::vector<Eigen::MatrixXd> grids(depths.size(),
                                     Eigen::MatrixXd::Constant(rows, grid_cols, -1.0));
  const double cell_w = static_cast<double>(pinhole.pinhole.width) / grid_cols;
  const double cell_h = static_cast<double>(pinhole.pinhole.height) / rows;
  ParallelFor(static_cast<size_t>(rows), num_threads, [&](size_t r) {
    for (int c = 0; c < grid_cols; ++c) {
      const Eigen::Vector2d pixel((c + 0.5) * cell_w, (static_cast<double>(r) + 0.5) * cell_h);
      for (size_t d = 0; d < depths.size(); ++d) {
        const std::optional<double> error = pinhole.ErrorAtDepth(pixel, depths[d]);
        if (error) grids[d](static_cast<Eigen::Index>(r), c) = *error;
      }
    }
  });
  ApproximationError result;
  for (size_t d = 0; d < depths.size(); ++d) {
    result.depths.push_back(Summarise(depths[d], std::move(grids[d])));
    if (result.depths.back().max_px >= result.worst_px) {
      result.worst_px = result.depths.back().max_px;
      result.worst_depth = depths[d];
    }
  }
  return result;
}

double ChooseDesignDepth(const HousedCamera& camera, const DepthRange& range,
                         const Eigen::Matrix3d& pinhole_from_cam,
                         const FieldOfViewOptions& field_of_view) {
  if (!camera.housing) return range.near;
  // The error grows away from the design depth on both sides (it is zero
  // there), so the worst over the range is unimodal in the design depth.
  const std::vector<double> depths = SampleDepths(range, 3, range.near);
  const double golden = (std::sqrt(5.0) - 1) / 2;
  double a = std::log(range.near), b = std::log(range.far);
  double x1 = b - golden * (b - a), x2 = a + golden * (b - a);
  double f1 = WorstError(camera, std::exp(x1), depths, pinhole_from_cam, field_of_view);
  double f2 = WorstError(camera, std::exp(x2), depths, pinhole_from_cam, field_of_view);
  for (int iteration = 0; iteration < 30 && b - a > 1e-4; ++iteration) {
    if (f1 <= f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - golden * (b - a);
      f1 = WorstError(camera, std::exp(x1), depths, pinhole_from_cam, field_of_view);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + golden * (b - a);
      f2 = WorstError(camera, std::exp(x2), depths, pinhole_from_cam, field_of_view);
    }
  }
  return std::exp(0.5 * (a + b));
}

}  // namespace portcal
