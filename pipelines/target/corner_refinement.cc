#include "pipelines/target/corner_refinement.h"

#include <ceres/ceres.h>

#include <cmath>

#include "colmap_ext/cost/corner_pattern_residual.h"
#include "colmap_ext/util/error.h"

namespace portcal {

void CornerRefinementOptions::Check() const {
  if (!(window_fraction > 0 && window_fraction <= 0.5)) {
    throw OptionError("window_fraction", std::to_string(window_fraction), "(0, 0.5]");
  }
  if (!(min_window_px >= 2 && max_window_px >= min_window_px)) {
    throw OptionError("min_window_px", std::to_string(min_window_px), ">= 2 and <= max_window_px");
  }
  if (!(max_shift_px > 0)) throw OptionError("max_shift_px", std::to_string(max_shift_px), "> 0");
  if (max_num_iterations < 1) {
    throw OptionError("max_num_iterations", std::to_string(max_num_iterations), ">= 1");
  }
}

namespace {

double NearestNeighbourDistance(const std::vector<Eigen::Vector2d>& corners, int cols, int rows,
                                int index) {
  const int r = index / cols, c = index % cols;
  double best = 1e300;
  for (const auto& [dr, dc] : {std::pair{0, 1}, std::pair{0, -1}, std::pair{1, 0}, std::pair{-1, 0}}) {
    const int rr = r + dr, cc = c + dc;
    if (rr < 0 || cc < 0 || rr >= rows || cc >= cols) continue;
    best = std::min(best, (corners[rr * cols + cc] - corners[index]).norm());
  }
  return best;
}

// Direction of the grid line through the corner along (dr, dc).
double EdgeAngle(const std::vector<Eigen::Vector2d>& corners, int cols, int rows, int index,
                 bool along_row) {
  const int r = index / cols, c = index % cols;
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  if (along_row) {
    if (c + 1 < cols) d += corners[index + 1] - corners[index];
    if (c > 0) d += corners[index] - corners[index - 1];
  } else {
    if (r + 1 < rows) d += corners[index + cols] - corners[index];
    if (r > 0) d += corners[index] - corners[index - cols];
  }
  // The edge normal is perpendicular to the line.
  return std::atan2(d.x(), -d.y());
}

}  // namespace

std::optional<RefinedCorner> RefineCorner(const cv::Mat& gray, const Eigen::Vector2d& start,
                                          double half, double normal_angle1, double normal_angle2,
                                          const CornerRefinementOptions& options) {
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  // Pixel centres (col + 0.5, row + 0.5) within the circular window.
  const int c0 = static_cast<int>(std::floor(start.x() - half));
  const int r0 = static_cast<int>(std::floor(start.y() - half));
  const int c1 = static_cast<int>(std::ceil(start.x() + half));
  const int r1 = static_cast<int>(std::ceil(start.y() + half));
  if (c0 < 0 || r0 < 0 || c1 >= gray.cols || r1 >= gray.rows) return std::nullopt;
  double params[7] = {start.x(), start.y(), normal_angle1, normal_angle2, 0, 0, std::log(0.3)};
  ceres::Problem problem;
  double sum = 0, count = 0;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const Eigen::Vector2d p(c + 0.5, r + 0.5);
      if ((p - start).norm() > half) continue;
      const double value = gray.at<uint8_t>(r, c);
      sum += value;
      ++count;
      problem.AddResidualBlock(CornerPatternResidual::Create(p.x(), p.y(), value), nullptr, params);
    }
  }
  if (count < 12) return std::nullopt;
  // Levels: the mean, and the contrast's sign from the quadrant between the
  // two edge normals.
  params[4] = sum / count;
  const Eigen::Vector2d probe =
      start + 0.5 * half * (Eigen::Vector2d(std::cos(params[2]), std::sin(params[2])) +
                            Eigen::Vector2d(std::cos(params[3]), std::sin(params[3])))
                               .normalized();
  params[5] = gray.at<uint8_t>(static_cast<int>(probe.y()), static_cast<int>(probe.x())) - params[4];
  if (std::abs(params[5]) < 5) return std::nullopt;  // no contrast
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_num_iterations;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  const Eigen::Vector2d xy(params[0], params[1]);
  if (!summary.IsSolutionUsable() || !xy.allFinite() || (xy - start).norm() > options.max_shift_px) {
    return std::nullopt;
  }
  RefinedCorner corner;
  corner.xy = xy;
  corner.rms_gray = std::sqrt(2 * summary.final_cost / count);
  corner.contrast = 2 * std::abs(params[5]);
  corner.blur_sigma_px = std::exp(params[6]);
  return corner;
}

std::vector<std::optional<RefinedCorner>> RefineChessboardCorners(
    const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols, int rows,
    const CornerRefinementOptions& options) {
  options.Check();
  PORTCAL_CHECK(static_cast<int>(corners.size()) == cols * rows);
  std::vector<std::optional<RefinedCorner>> refined(corners.size());
  for (int index = 0; index < cols * rows; ++index) {
    const double half = std::clamp(options.window_fraction *
                                       NearestNeighbourDistance(corners, cols, rows, index),
                                   options.min_window_px, options.max_window_px);
    refined[index] = RefineCorner(gray, corners[index], half, EdgeAngle(corners, cols, rows, index, true),
                                  EdgeAngle(corners, cols, rows, index, false), options);
  }
  return refined;
}

}  // namespace portcal
