#include "pipelines/crosscheck/projection_diff.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "pipelines/report/picture.h"

namespace portcal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Grid {
  int width = 0, height = 0;
  std::vector<Eigen::Vector2d> pixels;
};

// mrcal's grid: gridn_width points from the first to the last pixel centre.
Grid MakeGrid(const Camera& camera, int gridn_width) {
  Grid grid;
  grid.width = gridn_width;
  grid.height = std::max(2, static_cast<int>(std::lround(static_cast<double>(camera.height) /
                                                         camera.width * gridn_width)));
  for (int r = 0; r < grid.height; ++r) {
    for (int c = 0; c < grid.width; ++c) {
      grid.pixels.emplace_back(0.5 + (camera.width - 1.0) * c / (grid.width - 1),
                               0.5 + (camera.height - 1.0) * r / (grid.height - 1));
    }
  }
  return grid;
}

std::optional<Eigen::Vector3d> UnitRay(const Camera& camera, const Eigen::Vector2d& pixel) {
  const auto ray = camera.CamFromImg(pixel);
  if (!ray || !ray->allFinite()) return std::nullopt;
  return ray->normalized();
}

// Diff vectors (B's projection minus the grid pixel) after the weighted fit
// of b_from_a; NaN where a projection fails.
struct Evaluation {
  std::vector<Eigen::Vector2d> diff;
  Eigen::Matrix3d b_from_a = Eigen::Matrix3d::Identity();
};

// mrcal's fit of the rotation at infinity (implied_Rt10__from_unprojections):
// least squares on r_k = w_k * 2 (1 - v_b . R v_a), i.e. on the weighted
// squared angle between the rays, not the angle itself. Started from the
// Procrustes rotation (the weighted least-squares fit on the angle), then
// Levenberg-Marquardt on a rotation increment R <- exp(delta) R, for which
// dr_k / d delta = -2 w_k (R v_a x v_b).
Eigen::Matrix3d FitRotation(const std::vector<std::optional<Eigen::Vector3d>>& rays_a,
                            const std::vector<std::optional<Eigen::Vector3d>>& rays_b,
                            const std::vector<double>& weights) {
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < rays_a.size(); ++k) {
    if (rays_a[k] && rays_b[k] && weights[k] > 0)
      correlation += weights[k] * *rays_b[k] * rays_a[k]->transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Matrix3d rotation = svd.matrixU() * fix * svd.matrixV().transpose();
  // The residuals are of the order of the squared angles and so are their
  // second derivatives' contributions: plain Gauss-Newton may overshoot, so
  // steps are damped (Levenberg-Marquardt) and taken only when they lower the
  // cost, as mrcal's trust-region solver does.
  const auto cost = [&](const Eigen::Matrix3d& r) {
    double sum = 0;
    for (size_t k = 0; k < rays_a.size(); ++k) {
      if (!rays_a[k] || !rays_b[k] || weights[k] <= 0) continue;
      const double residual = weights[k] * 2 * (1 - rays_b[k]->dot(r * *rays_a[k]));
      sum += residual * residual;
    }
    return sum;
  };
  double current = cost(rotation);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 100 && current > 0; ++iteration) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < rays_a.size(); ++k) {
      if (!rays_a[k] || !rays_b[k] || weights[k] <= 0) continue;
      const Eigen::Vector3d u = rotation * *rays_a[k];
      const double r = weights[k] * 2 * (1 - rays_b[k]->dot(u));
      const Eigen::Vector3d j = -2 * weights[k] * u.cross(*rays_b[k]);
      jtj += j * j.transpose();
      jtr += j * r;
    }
    bool improved = false;
    while (lambda < 1e12) {
      Eigen::Matrix3d damped = jtj;
      damped.diagonal() *= 1 + lambda;
      const Eigen::Vector3d delta = -damped.ldlt().solve(jtr);
      if (!delta.allFinite()) break;
      const Eigen::Matrix3d candidate =
          (delta.norm() > 0 ? Eigen::AngleAxisd(delta.norm(), delta.normalized()).toRotationMatrix()
                            : Eigen::Matrix3d::Identity()) *
          rotation;
      const double next = cost(candidate);
      if (next < current) {
        improved = current - next > 1e-15 * current;
        rotation = candidate;
        current = next;
        lambda = std::max(1e-9, lambda / 10);
        break;
      }
      lambda *= 10;
    }
    if (!improved) break;
  }
  return rotation;
}

Evaluation Evaluate(const Camera& a, const Camera& b, const Grid& grid,
                    const std::vector<double>& weights) {
  const size_t n = grid.pixels.size();
  std::vector<std::optional<Eigen::Vector3d>> rays_a(n), rays_b(n);
  for (size_t k = 0; k < n; ++k) {
    rays_a[k] = UnitRay(a, grid.pixels[k]);
    if (rays_a[k] && weights[k] > 0) rays_b[k] = UnitRay(b, grid.pixels[k]);
  }
  Evaluation out;
  out.b_from_a = FitRotation(rays_a, rays_b, weights);
  out.diff.assign(n, Eigen::Vector2d::Constant(kNaN));
  for (size_t k = 0; k < n; ++k) {
    if (!rays_a[k]) continue;
    const auto pixel = b.ImgFromCam(out.b_from_a * *rays_a[k]);
    if (pixel && pixel->allFinite()) out.diff[k] = *pixel - grid.pixels[k];
  }
  return out;
}

// Central-difference step for parameter i: a hundredth of its standard
// deviation (the map is smooth on that scale; round-off is far below).
double Step(const Eigen::MatrixXd& covariance, int i) { return 1e-2 * std::sqrt(covariance(i, i)); }

using GridJacobian = Eigen::Matrix<double, 2, Eigen::Dynamic>;

// Per grid point, the derivative of a 2-vector `evaluate` computes (for all
// points at once) with respect to the lens parameters, by central
// differences; zero columns for parameters without variance (held).
std::vector<GridJacobian> GridJacobians(
    const CalibratedLens& lens, size_t n,
    const std::function<std::vector<Eigen::Vector2d>(const Camera&)>& evaluate) {
  const int p = static_cast<int>(lens.camera.params.size());
  std::vector<GridJacobian> jacobians(n, GridJacobian::Zero(2, p));
  for (int i = 0; i < p; ++i) {
    if (!(lens.covariance(i, i) > 0)) continue;
    const double h = Step(lens.covariance, i);
    Camera plus = lens.camera, minus = lens.camera;
    plus.params[i] += h;
    minus.params[i] -= h;
    const std::vector<Eigen::Vector2d> vp = evaluate(plus), vm = evaluate(minus);
    for (size_t k = 0; k < n; ++k) jacobians[k].col(i) = (vp[k] - vm[k]) / (2 * h);
  }
  return jacobians;
}

// Worst-direction projection standard deviation of a ray fixed in the camera
// frame (what mrcal weighs its fit with), from the intrinsics covariance.
std::vector<double> ProjectionStdDev(const CalibratedLens& lens, const Grid& grid) {
  const size_t n = grid.pixels.size();
  std::vector<std::optional<Eigen::Vector3d>> rays(n);
  for (size_t k = 0; k < n; ++k) rays[k] = UnitRay(lens.camera, grid.pixels[k]);
  const std::vector<GridJacobian> jacobians = GridJacobians(lens, n, [&](const Camera& camera) {
    std::vector<Eigen::Vector2d> pixels(n, Eigen::Vector2d::Constant(kNaN));
    for (size_t k = 0; k < n; ++k) {
      const auto q = rays[k] ? camera.ImgFromCam(*rays[k]) : std::nullopt;
      if (q) pixels[k] = *q;
    }
    return pixels;
  });
  std::vector<double> sigma(n, kNaN);
  for (size_t k = 0; k < n; ++k) {
    if (!rays[k] || !jacobians[k].allFinite()) continue;
    const Eigen::Matrix2d c = jacobians[k] * lens.covariance * jacobians[k].transpose();
    sigma[k] = std::sqrt(
        std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(c).eigenvalues().maxCoeff()));
  }
  return sigma;
}

// Adds tr(J C J^T) of one model's parameters to `variance`, J the Jacobian of
// the whole diff (fit included) with respect to them.
void AddPredictedVariance(const CalibratedLens& lens, bool lens_is_a, const Camera& other,
                          const Grid& grid, const std::vector<double>& weights,
                          std::vector<double>* variance) {
  const size_t n = grid.pixels.size();
  const std::vector<GridJacobian> jacobians = GridJacobians(lens, n, [&](const Camera& camera) {
    return (lens_is_a ? Evaluate(camera, other, grid, weights)
                      : Evaluate(other, camera, grid, weights))
        .diff;
  });
  for (size_t k = 0; k < n; ++k) {
    (*variance)[k] += (jacobians[k] * lens.covariance * jacobians[k].transpose()).trace();
  }
}

double Percentile(std::vector<double> values, double fraction) {
  values.erase(
      std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
      values.end());
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const size_t index =
      std::min(values.size() - 1, static_cast<size_t>(std::ceil(fraction * values.size())) - 1);
  return values[index];
}

const char* kRegionNames[3][3] = {{"top-left corner", "top edge", "top-right corner"},
                                  {"left edge", "centre", "right edge"},
                                  {"bottom-left corner", "bottom edge", "bottom-right corner"}};

// Each grid point's weight in the fit of the two models' relative
// rotation: 1 / (sigma_a sigma_b)^2 with both covariances (focus_radius
// < 0), else 1 within focus_radius (default: a sixth of the smaller image
// side) of the image centre.
std::vector<double> FitWeights(const CalibratedLens& a, const CalibratedLens& b, const Grid& grid,
                               bool with_covariance, const ProjectionDiffOptions& options) {
  const size_t n = grid.pixels.size();
  std::vector<double> weights(n, 0.0);
  if (with_covariance && options.focus_radius < 0) {
    const std::vector<double> sigma_a = ProjectionStdDev(a, grid);
    const std::vector<double> sigma_b = ProjectionStdDev(b, grid);
    for (size_t k = 0; k < n; ++k) {
      const double s = sigma_a[k] * sigma_b[k];
      weights[k] = std::isfinite(s) && s > 0 ? 1.0 / (s * s) : 0.0;
    }
  } else {
    const double radius = options.focus_radius < 0 ? std::min(a.camera.width, a.camera.height) / 6.0
                                                   : options.focus_radius;
    const Eigen::Vector2d centre(a.camera.width / 2.0, a.camera.height / 2.0);
    for (size_t k = 0; k < n; ++k) weights[k] = (grid.pixels[k] - centre).norm() <= radius;
  }
  return weights;
}

// The ninth of the image (3 x 3 regions) with the largest mean difference.
void FindWorstRegion(const Grid& grid, const Camera& camera, ProjectionDiff* out) {
  double region_sum[3][3] = {}, region_count[3][3] = {};
  for (size_t k = 0; k < grid.pixels.size(); ++k) {
    if (!std::isfinite(out->diff_px[k])) continue;
    const int r = std::min(2, static_cast<int>(3 * (grid.pixels[k].y() - 0.5) / camera.height));
    const int c = std::min(2, static_cast<int>(3 * (grid.pixels[k].x() - 0.5) / camera.width));
    region_sum[r][c] += out->diff_px[k];
    region_count[r][c] += 1;
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (region_count[r][c] == 0) continue;
      const double mean = region_sum[r][c] / region_count[r][c];
      if (mean >= out->worst_region_mean_px) {
        out->worst_region_mean_px = mean;
        out->worst_region = kRegionNames[r][c];
      }
    }
  }
}

// The difference the two models' uncertainties predict at each grid point.
void PredictDiff(const CalibratedLens& a, const CalibratedLens& b, const Grid& grid,
                 const std::vector<double>& weights, int num_valid, ProjectionDiff* out) {
  const size_t n = grid.pixels.size();
  std::vector<double> variance(n, 0.0);
  AddPredictedVariance(a, true, b.camera, grid, weights, &variance);
  AddPredictedVariance(b, false, a.camera, grid, weights, &variance);
  out->predicted_px.resize(n);
  double predicted_sum = 0;
  for (size_t k = 0; k < n; ++k) {
    out->predicted_px[k] = std::isfinite(out->diff_px[k]) ? std::sqrt(variance[k]) : kNaN;
    if (std::isfinite(out->predicted_px[k])) predicted_sum += out->predicted_px[k];
  }
  out->predicted_mean_px = predicted_sum / num_valid;
  out->predicted_p95_px = Percentile(out->predicted_px, 0.95);
}

}  // namespace

void ProjectionDiffOptions::Check() const {
  if (gridn_width < 3) throw OptionError("gridn_width", gridn_width, ">= 3");
}

ProjectionDiff ComputeProjectionDiff(const CalibratedLens& a, const CalibratedLens& b,
                                     const ProjectionDiffOptions& options) {
  options.Check();
  if (a.camera.width != b.camera.width || a.camera.height != b.camera.height) {
    throw InputError("projection diff: image sizes differ (" + std::to_string(a.camera.width) +
                     "x" + std::to_string(a.camera.height) + " vs " +
                     std::to_string(b.camera.width) + "x" + std::to_string(b.camera.height) + ")");
  }
  const Grid grid = MakeGrid(a.camera, options.gridn_width);
  const size_t n = grid.pixels.size();
  const bool with_covariance = a.covariance.size() > 0 && b.covariance.size() > 0;
  const std::vector<double> weights = FitWeights(a, b, grid, with_covariance, options);
  const Evaluation evaluation = Evaluate(a.camera, b.camera, grid, weights);
  ProjectionDiff out;
  out.grid_width = grid.width;
  out.grid_height = grid.height;
  out.pixels = grid.pixels;
  out.b_from_a = evaluation.b_from_a;
  out.diff_px.resize(n);
  int valid = 0;
  double sum = 0;
  for (size_t k = 0; k < n; ++k) {
    out.diff_px[k] = evaluation.diff[k].norm();
    if (std::isfinite(out.diff_px[k])) {
      ++valid;
      sum += out.diff_px[k];
      out.max_px = std::max(out.max_px, out.diff_px[k]);
    }
  }
  if (valid < static_cast<int>(n) / 2) {
    throw NumericalError("projection diff: only " + std::to_string(valid) + " of " +
                         std::to_string(n) + " grid points project through both cameras");
  }
  out.mean_px = sum / valid;
  out.p95_px = Percentile(out.diff_px, 0.95);
  FindWorstRegion(grid, a.camera, &out);
  if (with_covariance) PredictDiff(a, b, grid, weights, valid, &out);
  return out;
}

void WriteProjectionDiffHeatMap(const ProjectionDiff& diff, int width, int height,
                                const std::string& title, const std::filesystem::path& path) {
  Eigen::MatrixXd grid(diff.grid_height, diff.grid_width);
  for (int r = 0; r < diff.grid_height; ++r) {
    for (int c = 0; c < diff.grid_width; ++c) {
      const double v = diff.diff_px[r * diff.grid_width + c];
      grid(r, c) = std::isfinite(v) ? v : -1.0;
    }
  }
  std::ostringstream heading;
  heading << std::setprecision(3) << title << ": mean " << diff.mean_px << ", p95 " << diff.p95_px
          << ", max " << diff.max_px << " px (lines: mean, p95)";
  HeatMapStyle style;
  style.title = heading.str();
  style.unit = "px";
  style.contour_levels = {diff.mean_px, diff.p95_px};
  style.max_value = diff.max_px;
  WritePng(HeatMapPicture(grid, width, height, style), path);
}

}  // namespace portcal
