#include "pipelines/guidance/projection_uncertainty.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

// "Infinity": far enough that the targets' translations (metres) change
// nothing below 1e-6 of the result, near enough for the refraction's
// arithmetic.
constexpr double kInfinityM = 1e6;

// The worst-direction standard deviation of a 2 x 2 covariance.
double WorstDirection(const Eigen::Matrix2d& covariance) {
  const double a = covariance(0, 0), b = 0.5 * (covariance(0, 1) + covariance(1, 0)),
               c = covariance(1, 1);
  return std::sqrt(std::max(0.0, 0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + b * b)));
}

// sigma^2 times the inverse of the information on the unknowns; empty when
// the views do not fix them. Scaled to unit diagonal, so that the rank
// test does not depend on the unknowns' units (a focal length in pixels
// beside k2).
Eigen::MatrixXd UnknownsCovariance(const Eigen::MatrixXd& information, double pixel_sigma_px) {
  const Eigen::VectorXd diagonal = information.diagonal();
  if (!(diagonal.minCoeff() > 0)) return Eigen::MatrixXd();
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd normalised = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normalised);
  if (eigen.info() != Eigen::Success ||
      !(eigen.eigenvalues().minCoeff() > 1e-9 * eigen.eigenvalues().maxCoeff())) {
    return Eigen::MatrixXd();
  }
  const Eigen::MatrixXd inverse_normalised = eigen.eigenvectors() *
                                             eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                             eigen.eigenvectors().transpose();
  return pixel_sigma_px * pixel_sigma_px * scale.asDiagonal() * inverse_normalised *
         scale.asDiagonal();
}

void Summarise(const Eigen::MatrixXd& map, double* mean, double* max) {
  double sum = 0;
  int count = 0;
  for (Eigen::Index k = 0; k < map.size(); ++k) {
    if (map(k) < 0) continue;
    sum += map(k);
    *max = std::max(*max, map(k));
    ++count;
  }
  *mean = count > 0 ? sum / count : 0;
}

}  // namespace

void ProjectionUncertaintyOptions::Check() const {
  if (!(working_distance_m > 0)) {
    throw OptionError("working_distance", working_distance_m, "> 0 m");
  }
  if (grid_cols < 2 || grid_rows < 2) {
    throw OptionError("uncertainty grid",
                      std::to_string(grid_cols) + "x" + std::to_string(grid_rows), ">= 2x2");
  }
  if (!(pixel_sigma_px > 0)) throw OptionError("pixel sigma", pixel_sigma_px, "> 0 px");
}

// Cell centres: the image's edge itself is where few cameras are used.
Eigen::VectorXd UncertaintyGridColumns(double image_width, int grid_cols) {
  Eigen::VectorXd x(grid_cols);
  for (int c = 0; c < grid_cols; ++c) x[c] = (c + 0.5) * image_width / grid_cols;
  return x;
}

Eigen::VectorXd UncertaintyGridRows(double image_height, int grid_rows) {
  return UncertaintyGridColumns(image_height, grid_rows);
}

ProjectionUncertaintyModel::ProjectionUncertaintyModel(const CalibrationUnknowns& unknowns,
                                                       const ProjectionUncertaintyOptions& options)
    : options_(options), num_unknowns_(unknowns.NumUnknowns()) {
  options.Check();
  const Camera& camera = unknowns.camera.camera;
  const Eigen::VectorXd xs =
      UncertaintyGridColumns(static_cast<double>(camera.width), options.grid_cols);
  const Eigen::VectorXd ys =
      UncertaintyGridRows(static_cast<double>(camera.height), options.grid_rows);
  for (int r = 0; r < options.grid_rows; ++r) {
    for (int c = 0; c < options.grid_cols; ++c) {
      const std::optional<Ray3d> ray = unknowns.camera.Unproject(Eigen::Vector2d(xs[c], ys[r]));
      const bool usable =
          ray && ray->direction.z() > 1e-6 && ray->origin.z() < options.working_distance_m;
      projects_.push_back(usable);
      const auto at_depth = [&](double z) {
        // Does not project: zero rows.
        return usable ? Eigen::Vector3d(ray->origin +
                                        (z - ray->origin.z()) / ray->direction.z() * ray->direction)
                      : Eigen::Vector3d(0, 0, -1);
      };
      at_distance_.points.push_back(at_depth(options.working_distance_m));
      at_infinity_.points.push_back(at_depth(kInfinityM));
    }
  }
  at_distance_.jacobians = ProjectionJacobian(unknowns, at_distance_.points);
  at_infinity_.jacobians = ProjectionJacobian(unknowns, at_infinity_.points);
}

Eigen::MatrixXd ProjectionUncertaintyModel::Sigmas(const GridPoints& grid,
                                                   const CalibrationInformation& information,
                                                   const Eigen::MatrixXd& covariance) const {
  Eigen::MatrixXd map = Eigen::MatrixXd::Constant(options_.grid_rows, options_.grid_cols, -1.0);
  const double variance = options_.pixel_sigma_px * options_.pixel_sigma_px;
  for (int k = 0; k < static_cast<int>(projects_.size()); ++k) {
    if (!projects_[static_cast<size_t>(k)]) continue;
    const Eigen::Vector3d& point = grid.points[static_cast<size_t>(k)];
    const Eigen::MatrixXd d_point = grid.jacobians.point.middleRows(2 * k, 2);
    // The unknowns' error, less what the targets' frames take back of it,
    // then the frames' own noise.
    const Eigen::MatrixXd gain =
        grid.jacobians.unknowns.middleRows(2 * k, 2) - d_point * information.MeanFrameGain(point);
    const Eigen::Matrix2d pixel_covariance =
        gain * covariance * gain.transpose() +
        variance * d_point * information.MeanFrameNoise(point) * d_point.transpose();
    map(k / options_.grid_cols, k % options_.grid_cols) = WorstDirection(pixel_covariance);
  }
  return map;
}

ProjectionUncertainty ProjectionUncertaintyModel::Evaluate(
    const CalibrationInformation& information) const {
  ProjectionUncertainty result;
  result.map_px = Eigen::MatrixXd::Constant(options_.grid_rows, options_.grid_cols, -1.0);
  result.map_at_infinity_px = result.map_px;
  if (num_unknowns_ == 0) {
    result.determined = true;
    result.map_px.setZero();
    result.map_at_infinity_px.setZero();
    return result;
  }
  PORTCAL_CHECK(information.NumUnknowns() == num_unknowns_);
  const Eigen::MatrixXd covariance =
      UnknownsCovariance(information.reduced, options_.pixel_sigma_px);
  if (covariance.size() == 0) return result;
  result.determined = true;
  result.map_px = Sigmas(at_distance_, information, covariance);
  result.map_at_infinity_px = Sigmas(at_infinity_, information, covariance);
  Summarise(result.map_px, &result.mean_px, &result.max_px);
  Summarise(result.map_at_infinity_px, &result.mean_at_infinity_px, &result.max_at_infinity_px);
  return result;
}

}  // namespace portcal
