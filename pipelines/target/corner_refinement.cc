#include "pipelines/target/corner_refinement.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "colmap_ext/cost/corner_pattern_model.h"
#include "colmap_ext/util/error.h"
#include "pipelines/target/board_shading.h"

namespace portcal {

void CornerRefinementOptions::Check() const {
  if (!(window_fraction > 0 && window_fraction <= 0.5)) {
    throw OptionError("window_fraction", window_fraction, "(0, 0.5]");
  }
  if (!(min_window_px >= 2 && max_window_px >= min_window_px)) {
    throw OptionError("min_window_px", min_window_px, ">= 2 and <= max_window_px");
  }
  if (!(max_shift_px > 0)) throw OptionError("max_shift_px", max_shift_px, "> 0");
  if (!(max_shift_fraction >= 0 && max_shift_fraction < 0.5)) {
    throw OptionError("max_shift_fraction", max_shift_fraction, "[0, 0.5)");
  }
  if (max_num_iterations < 1) {
    throw OptionError("max_num_iterations", max_num_iterations, ">= 1");
  }
  if (!std::isfinite(max_level_drift)) {
    throw OptionError("--Target.max_level_drift", max_level_drift, "a fraction (< 0: never)");
  }
  if (!(corner_tolerance_px > 0)) {
    throw OptionError("corner_tolerance_px", corner_tolerance_px, "> 0");
  }
}

const char* CornerFailureText(CornerFailure failure) {
  switch (failure) {
    case CornerFailure::kNone:
      return "refined";
    case CornerFailure::kNearImageBorder:
      return "window beyond the image";
    case CornerFailure::kNoContrast:
      return "no contrast";
    case CornerFailure::kDiverged:
      return "fit diverged";
    case CornerFailure::kMovedTooFar:
      return "moved too far from the detection";
    case CornerFailure::kNotSeen:
      return "out of view";
  }
  return "unknown";
}

namespace {

double NearestNeighbourDistance(const std::vector<Eigen::Vector2d>& corners, int cols, int rows,
                                int index) {
  const int r = index / cols, c = index % cols;
  double best = 1e300;
  for (const auto& [dr, dc] :
       {std::pair{0, 1}, std::pair{0, -1}, std::pair{1, 0}, std::pair{-1, 0}}) {
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

struct WindowPixel {
  double x, y, gray;  // the pixel's centre (COLMAP pixels) and its gray
  CornerPatternModel::Region region = CornerPatternModel::kCorner;  // for kArea
};

using Vector7d = Eigen::Matrix<double, 7, 1>;
using Matrix7d = Eigen::Matrix<double, 7, 7>;

// How the model is integrated over each pixel in a fit.
struct Integration {
  bool area = false;                               // false: the pixel's centre only
  PixelRule corner_rule = PixelRule::Midpoint(4);  // where both edges vary over a pixel
};

// J^T J, J^T r and the cost at p. A flat pixel's gradient has two
// entries, 1 for the mean and its sign for the contrast: their sums are
// gathered apart, which saves a rank-one update for most pixels of a sharp
// corner's window.
double Linearise(const std::vector<WindowPixel>& window, const Vector7d& p,
                 const Integration& integration, Matrix7d* jtj, Vector7d* jtr) {
  const CornerPatternModel model(
      p.data(), integration.area ? integration.corner_rule : PixelRule::Midpoint(1));
  jtj->setZero();
  jtr->setZero();
  double cost = 0;
  double flat_count = 0, flat_sign_sum = 0, flat_residual_sum = 0, flat_signed_residual_sum = 0;
  Vector7d gradient;
  for (const WindowPixel& pixel : window) {
    const double value = integration.area
                             ? model.EvaluateArea(pixel.x, pixel.y, pixel.region, gradient.data())
                             : model.Evaluate(pixel.x, pixel.y, gradient.data());
    const double r = value - pixel.gray;
    cost += 0.5 * r * r;
    if (integration.area && pixel.region == CornerPatternModel::kFlat) {
      flat_count += 1;
      flat_sign_sum += gradient[5];
      flat_residual_sum += r;
      flat_signed_residual_sum += r * gradient[5];
      continue;
    }
    jtj->noalias() += gradient * gradient.transpose();  // fixed 7 x 7: faster than a rank update
    *jtr += r * gradient;
  }
  (*jtj)(4, 4) += flat_count;
  (*jtj)(5, 4) += flat_sign_sum;
  (*jtj)(4, 5) += flat_sign_sum;
  (*jtj)(5, 5) += flat_count;  // sign^2
  (*jtr)(4) += flat_residual_sum;
  (*jtr)(5) += flat_signed_residual_sum;
  return cost;
}

// Levenberg-Marquardt on the 7 parameters as Ceres runs it (the damping
// diag(J^T J) / radius, the radius grown by 1 / max(1/3, 1 - (2 rho - 1)^3)
// on success and shrunk by a doubling factor on failure; Ceres' default
// function, parameter and gradient tolerances), with the Jacobian written
// out and nothing allocated per iteration. A trial step is linearised at
// once: most steps are taken, and their cost would otherwise be evaluated
// twice. Returns the final cost, or a negative value when the fit broke
// down (non-finite).
double FitCornerPattern(const std::vector<WindowPixel>& window, const Integration& integration,
                        int max_num_iterations, double corner_tolerance_px, Vector7d* p) {
  Matrix7d jtj, trial_jtj;
  Vector7d jtr, trial_jtr;
  double cost = Linearise(window, *p, integration, &jtj, &jtr);
  double radius = 1e4, decrease_factor = 2;
  for (int iteration = 0; iteration < max_num_iterations; ++iteration) {
    if (!std::isfinite(cost)) return -1;
    if (jtr.lpNorm<Eigen::Infinity>() <= 1e-10) break;
    Matrix7d damped = jtj;
    damped.diagonal() += jtj.diagonal().cwiseMax(1e-6).cwiseMin(1e32) / radius;
    const Vector7d step = damped.ldlt().solve(-jtr);
    if (!step.allFinite()) return -1;
    if (step.norm() <= 1e-8 * (p->norm() + 1e-8)) break;
    const Vector7d trial = *p + step;
    const double trial_cost = Linearise(window, trial, integration, &trial_jtj, &trial_jtr);
    const double model_decrease = -(jtr.dot(step) + 0.5 * step.dot(jtj * step));
    const double rho = model_decrease > 0 ? (cost - trial_cost) / model_decrease : -1;
    if (std::isfinite(trial_cost) && rho > 1e-3) {
      const double old_cost = cost;
      *p = trial;
      cost = trial_cost;
      jtj = trial_jtj;
      jtr = trial_jtr;
      radius = std::min(1e16, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2 * rho - 1, 3)));
      decrease_factor = 2;
      if (old_cost - cost <= 1e-6 * old_cost || step.head<2>().norm() < corner_tolerance_px) break;
    } else {
      radius /= decrease_factor;
      decrease_factor *= 2;
      if (radius < 1e-32) break;
    }
  }
  return std::isfinite(cost) ? cost : -1;
}

// The fit integrating over each pixel's area, from p near the minimum.
// Which edges vary over which pixel is decided first (with a margin for the
// corner's move) and kept through the fit, so that the model stays smooth;
// should the fit end where a pixel's region no longer holds, it is decided
// again and the fit rerun. Where both edges vary over a pixel the product
// of their erfs is averaged by Gauss-Legendre while the edges are smooth at
// the pixel's scale, and by 8 x 8 sub-samples when they are sharp (a few
// pixels only then).
double FitOverPixelAreas(const CornerRefinementOptions& options, std::vector<WindowPixel>* window,
                         Vector7d* p) {
  const CornerPatternModel start(p->data());
  const double span = start.PixelSpan();
  const Integration integration{true, span <= 1.5 ? PixelRule::GaussLegendre(3)
                                      : span <= 3 ? PixelRule::GaussLegendre(5)
                                                  : PixelRule::Midpoint(8)};
  constexpr double margin = 0.5;  // erf's units: sqrt(2) sigma pixels
  for (WindowPixel& pixel : *window) pixel.region = start.Classify(pixel.x, pixel.y, margin);
  double cost = FitCornerPattern(*window, integration, options.max_num_iterations,
                                 options.corner_tolerance_px, p);
  for (int refit = 0; refit < 2 && cost >= 0; ++refit) {
    const CornerPatternModel end(p->data());
    bool changed = false;
    for (WindowPixel& pixel : *window) {
      if ((end.Classify(pixel.x, pixel.y, 0) & ~pixel.region) == 0) continue;
      pixel.region = static_cast<CornerPatternModel::Region>(
          pixel.region | end.Classify(pixel.x, pixel.y, margin));
      changed = true;
    }
    if (!changed) break;
    cost = FitCornerPattern(*window, integration, options.max_num_iterations,
                            options.corner_tolerance_px, p);
  }
  return cost;
}

// The pixels (centres col + 0.5, row + 0.5) within the circular window of
// radius `half` about `centre`, their grays brought to the levels at
// `shading_centre` by `shading` if given; empty where the window leaves
// the image.
std::vector<WindowPixel> WindowAbout(
    const cv::Mat& gray, const Eigen::Vector2d& centre, double half,
    const LocalShading* shading = nullptr,
    const Eigen::Vector2d& shading_centre = Eigen::Vector2d::Zero()) {
  const int c0 = static_cast<int>(std::floor(centre.x() - half));
  const int r0 = static_cast<int>(std::floor(centre.y() - half));
  const int c1 = static_cast<int>(std::ceil(centre.x() + half));
  const int r1 = static_cast<int>(std::ceil(centre.y() + half));
  std::vector<WindowPixel> window;
  if (c0 < 0 || r0 < 0 || c1 >= gray.cols || r1 >= gray.rows) return window;
  window.reserve(static_cast<size_t>((c1 - c0 + 1) * (r1 - r0 + 1)));
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const Eigen::Vector2d p(c + 0.5, r + 0.5);
      if ((p - centre).norm() > half) continue;
      const double value = gray.at<uint8_t>(r, c);
      window.push_back(
          {p.x(), p.y(), shading != nullptr ? shading->Flatten(value, p - shading_centre) : value});
    }
  }
  return window;
}

// The first stage of a corner's fit: the pattern fitted at the window's
// pixel centres only (the blur absorbs the pixel's box), from the start's
// levels and edge angles. kNone, or why the fit cannot go on.
CornerFailure FitAtPixelCentres(const cv::Mat& gray, const std::vector<WindowPixel>& window,
                                const Eigen::Vector2d& start, double half, double normal_angle1,
                                double normal_angle2, const CornerRefinementOptions& options,
                                Vector7d* params) {
  if (window.size() < 12) return CornerFailure::kNearImageBorder;
  double sum = 0;
  for (const WindowPixel& pixel : window) sum += pixel.gray;
  // Levels: the mean, and the contrast's sign from the quadrant between the
  // two edge normals.
  *params << start.x(), start.y(), normal_angle1, normal_angle2, sum / window.size(), 0,
      std::log(0.8);
  const Eigen::Vector2d probe =
      start + 0.5 * half *
                  (Eigen::Vector2d(std::cos(normal_angle1), std::sin(normal_angle1)) +
                   Eigen::Vector2d(std::cos(normal_angle2), std::sin(normal_angle2)))
                      .normalized();
  (*params)[5] =
      gray.at<uint8_t>(static_cast<int>(probe.y()), static_cast<int>(probe.x())) - (*params)[4];
  if (std::abs((*params)[5]) < 5) return CornerFailure::kNoContrast;
  // Near the minimum the steps shrink geometrically (the sharp edges'
  // curvature, which Gauss-Newton leaves out), so this stage stops once
  // the corner moves by less than 0.01 px; the second goes on from there.
  if (FitCornerPattern(window, Integration{}, options.max_num_iterations, 0.01, params) < 0) {
    return CornerFailure::kDiverged;
  }
  // The blur less the pixel's box (variance 1/12 px^2 across any edge).
  (*params)[6] = 0.5 * std::log(std::max(std::exp(2 * (*params)[6]) - 1.0 / 12, 0.01));
  return CornerFailure::kNone;
}

// The second stage: the pattern integrated over each pixel's area, from
// the first stage's parameters; the corner, or why not.
std::optional<RefinedCorner> FitOverAreas(std::vector<WindowPixel>* window,
                                          const Eigen::Vector2d& start,
                                          const CornerRefinementOptions& options, Vector7d* params,
                                          CornerFailure* failure) {
  const double final_cost = FitOverPixelAreas(options, window, params);
  const Eigen::Vector2d xy((*params)[0], (*params)[1]);
  *failure = final_cost < 0 || !params->allFinite()       ? CornerFailure::kDiverged
             : (xy - start).norm() > options.max_shift_px ? CornerFailure::kMovedTooFar
                                                          : CornerFailure::kNone;
  if (*failure != CornerFailure::kNone) return std::nullopt;
  RefinedCorner corner;
  corner.xy = xy;
  corner.rms_gray = std::sqrt(2 * final_cost / static_cast<double>(window->size()));
  corner.contrast = 2 * std::abs((*params)[5]);
  corner.blur_sigma_px = std::exp((*params)[6]);
  corner.mean_gray = (*params)[4];
  return corner;
}

}  // namespace

std::optional<RefinedCorner> RefineCorner(const cv::Mat& gray, const Eigen::Vector2d& start,
                                          double half, double normal_angle1, double normal_angle2,
                                          const CornerRefinementOptions& options,
                                          CornerFailure* failure) {
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  CornerFailure unused;
  if (failure == nullptr) failure = &unused;
  std::vector<WindowPixel> window = WindowAbout(gray, start, half);
  Vector7d params;
  *failure =
      FitAtPixelCentres(gray, window, start, half, normal_angle1, normal_angle2, options, &params);
  if (*failure != CornerFailure::kNone) return std::nullopt;
  return FitOverAreas(&window, start, options, &params, failure);
}

namespace {

// One grid corner through both stages of its fit.
struct GridCorner {
  Eigen::Vector2d start;
  double half = 0;
  CornerRefinementOptions options;  // its own max_shift_px
  Vector7d params;
  CornerFailure failure = CornerFailure::kNone;
};

// The board's shading (board_shading.h) from the first stage's levels;
// nullopt with too few corners.
std::optional<BoardShading> ShadingOfFirstStage(const std::vector<GridCorner>& grid) {
  std::vector<Eigen::Vector2d> xy;
  std::vector<double> means, contrasts;
  for (const GridCorner& corner : grid) {
    if (corner.failure != CornerFailure::kNone) continue;
    xy.emplace_back(corner.params[0], corner.params[1]);
    means.push_back(corner.params[4]);
    contrasts.push_back(2 * std::abs(corner.params[5]));
  }
  return BoardShading::Fit(xy, means, contrasts);
}

}  // namespace

std::vector<std::optional<RefinedCorner>> RefineBoardCorners(const cv::Mat& gray,
                                                             const std::vector<CornerStart>& starts,
                                                             const CornerRefinementOptions& options,
                                                             std::vector<CornerFailure>* failures) {
  options.Check();
  PORTCAL_CHECK(gray.type() == CV_8UC1);
  std::vector<GridCorner> grid(starts.size());
  for (size_t index = 0; index < starts.size(); ++index) {
    const CornerStart& start = starts[index];
    GridCorner& corner = grid[index];
    corner.start = start.xy;
    corner.half = start.half_window_px;
    corner.options = options;
    corner.options.max_shift_px = start.max_shift_px;
    corner.failure =
        start.seen ? FitAtPixelCentres(gray, WindowAbout(gray, start.xy, start.half_window_px),
                                       start.xy, start.half_window_px, start.normal_angle1,
                                       start.normal_angle2, corner.options, &corner.params)
                   : CornerFailure::kNotSeen;
  }
  // The second stage over windows brought to each corner's own levels
  // where the board's levels drift across them.
  const std::optional<BoardShading> shading =
      options.max_level_drift >= 0 ? ShadingOfFirstStage(grid) : std::nullopt;
  std::vector<std::optional<RefinedCorner>> refined(starts.size());
  for (size_t index = 0; index < grid.size(); ++index) {
    GridCorner& corner = grid[index];
    if (corner.failure != CornerFailure::kNone) continue;
    const Eigen::Vector2d xy(corner.params[0], corner.params[1]);
    const std::optional<LocalShading> local =
        shading ? std::optional(shading->At(xy)) : std::nullopt;
    // A drift of a quarter of the contrast across one window is no shading
    // but a field fitted to wild levels (a handful of corners, one a
    // reflection): such a window is left as it is.
    const double drift = local ? local->Drift(corner.half, 2 * std::abs(corner.params[5])) : 0;
    const bool flatten = local && drift > options.max_level_drift && drift < 0.25;
    std::vector<WindowPixel> window =
        flatten ? WindowAbout(gray, corner.start, corner.half, &*local, xy)
                : WindowAbout(gray, corner.start, corner.half);
    refined[index] =
        FitOverAreas(&window, corner.start, corner.options, &corner.params, &corner.failure);
  }
  if (failures != nullptr) {
    failures->clear();
    for (const GridCorner& corner : grid) failures->push_back(corner.failure);
  }
  return refined;
}

std::vector<std::optional<RefinedCorner>> RefineChessboardCorners(
    const cv::Mat& gray, const std::vector<Eigen::Vector2d>& corners, int cols, int rows,
    const CornerRefinementOptions& options, std::vector<CornerFailure>* failures,
    const std::vector<bool>* seen) {
  PORTCAL_CHECK(static_cast<int>(corners.size()) == cols * rows);
  PORTCAL_CHECK(seen == nullptr || seen->size() == corners.size());
  std::vector<CornerStart> starts(corners.size());
  for (int index = 0; index < cols * rows; ++index) {
    const double neighbour_distance = NearestNeighbourDistance(corners, cols, rows, index);
    CornerStart& start = starts[index];
    start.xy = corners[index];
    start.half_window_px = std::clamp(options.window_fraction * neighbour_distance,
                                      options.min_window_px, options.max_window_px);
    start.normal_angle1 = EdgeAngle(corners, cols, rows, index, true);
    start.normal_angle2 = EdgeAngle(corners, cols, rows, index, false);
    start.max_shift_px =
        std::max(options.max_shift_px, options.max_shift_fraction * neighbour_distance);
    start.seen = seen == nullptr || (*seen)[index];
  }
  return RefineBoardCorners(gray, starts, options, failures);
}

}  // namespace portcal
