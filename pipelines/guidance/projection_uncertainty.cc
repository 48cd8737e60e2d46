#include "pipelines/guidance/projection_uncertainty.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {

void ProjectionUncertaintyOptions::Check() const {
  if (!(working_distance_m > 0)) {
    throw OptionError("working_distance", std::to_string(working_distance_m), "> 0 m");
  }
  if (grid_cols < 2 || grid_rows < 2) {
    throw OptionError("uncertainty grid", std::to_string(grid_cols) + "x" + std::to_string(grid_rows), ">= 2x2");
  }
  if (!(pixel_sigma_px > 0)) throw OptionError("pixel sigma", std::to_string(pixel_sigma_px), "> 0 px");
}

ProjectionUncertaintyModel::ProjectionUncertaintyModel(const CalibrationUnknowns& unknowns,
                                                       const ProjectionUncertaintyOptions& options)
    : options_(options), num_unknowns_(unknowns.NumUnknowns()) {
  options.Check();
  const Camera& camera = unknowns.camera.camera;
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < options.grid_rows; ++r) {
    for (int c = 0; c < options.grid_cols; ++c) {
      // Cell centres: the image's edge itself is where few cameras are used.
      const Eigen::Vector2d pixel((c + 0.5) * camera.width / options.grid_cols,
                                  (r + 0.5) * camera.height / options.grid_rows);
      const std::optional<Ray3d> ray = unknowns.camera.Unproject(pixel);
      const bool usable = ray && ray->direction.z() > 1e-6 && ray->origin.z() < options.working_distance_m;
      projects_.push_back(usable);
      points.push_back(usable ? Eigen::Vector3d(ray->origin + (options.working_distance_m - ray->origin.z()) /
                                                                  ray->direction.z() * ray->direction)
                              : Eigen::Vector3d(0, 0, -1));  // does not project: zero rows
    }
  }
  jacobian_ = ProjectionJacobian(unknowns, points);
}

ProjectionUncertainty ProjectionUncertaintyModel::Evaluate(const Eigen::MatrixXd& information) const {
  ProjectionUncertainty result;
  result.map_px = Eigen::MatrixXd::Constant(options_.grid_rows, options_.grid_cols, -1.0);
  if (num_unknowns_ == 0) {
    result.determined = true;
    result.map_px.setZero();
    return result;
  }
  // Scaled to unit diagonal, so that the rank test does not depend on the
  // unknowns' units (a focal length in pixels beside k2).
  const Eigen::VectorXd diagonal = information.diagonal();
  if (!(diagonal.minCoeff() > 0)) return result;
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd normalised = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normalised);
  if (eigen.info() != Eigen::Success || !(eigen.eigenvalues().minCoeff() > 1e-9 * eigen.eigenvalues().maxCoeff())) {
    return result;
  }
  const Eigen::MatrixXd inverse_normalised =
      eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  const Eigen::MatrixXd covariance = options_.pixel_sigma_px * options_.pixel_sigma_px * scale.asDiagonal() *
                                     inverse_normalised * scale.asDiagonal();
  result.determined = true;
  double sum = 0;
  int count = 0;
  for (int k = 0; k < static_cast<int>(projects_.size()); ++k) {
    if (!projects_[static_cast<size_t>(k)]) continue;
    const Eigen::MatrixXd j = jacobian_.middleRows(2 * k, 2);
    const Eigen::Matrix2d pixel_covariance = j * covariance * j.transpose();
    const double worst = std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(pixel_covariance,
                                                                                              Eigen::EigenvaluesOnly)
                                                     .eigenvalues()
                                                     .maxCoeff()));
    result.map_px(k / options_.grid_cols, k % options_.grid_cols) = worst;
    sum += worst;
    result.max_px = std::max(result.max_px, worst);
    ++count;
  }
  result.mean_px = count > 0 ? sum / count : 0;
  return result;
}

}  // namespace portcal
