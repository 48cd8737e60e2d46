#include "pipelines/target/board_shading.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

namespace portcal {
namespace {

// Least squares of values ~ basis, refitted without the points beyond
// 3 robust sigmas of the first fit's residuals.
Eigen::VectorXd RobustFit(const Eigen::MatrixXd& basis, const Eigen::VectorXd& values) {
  Eigen::VectorXd fit = basis.colPivHouseholderQr().solve(values);
  const Eigen::VectorXd residuals = values - basis * fit;
  std::vector<double> magnitudes(residuals.size());
  for (Eigen::Index i = 0; i < residuals.size(); ++i) magnitudes[i] = std::abs(residuals[i]);
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                   magnitudes.end());
  const double limit = 3 * 1.4826 * magnitudes[magnitudes.size() / 2];
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < residuals.size(); ++i) {
    if (std::abs(residuals[i]) <= limit) kept.push_back(i);
  }
  if (static_cast<Eigen::Index>(kept.size()) == residuals.size() ||
      kept.size() < 2 * size_t(basis.cols()))
    return fit;
  Eigen::MatrixXd kept_basis(kept.size(), basis.cols());
  Eigen::VectorXd kept_values(kept.size());
  for (size_t k = 0; k < kept.size(); ++k) {
    kept_basis.row(k) = basis.row(kept[k]);
    kept_values[k] = values[kept[k]];
  }
  return kept_basis.colPivHouseholderQr().solve(kept_values);
}

}  // namespace

Eigen::VectorXd BoardShading::Basis(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d u = (point - centre_) / scale_;
  Eigen::VectorXd basis(num_terms_);
  basis.head<3>() << 1, u.x(), u.y();
  if (num_terms_ == 6) basis.tail<3>() << u.x() * u.x(), u.x() * u.y(), u.y() * u.y();
  return basis;
}

Eigen::MatrixXd BoardShading::BasisGradient(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d u = (point - centre_) / scale_;
  Eigen::MatrixXd gradient = Eigen::MatrixXd::Zero(2, num_terms_);
  gradient(0, 1) = gradient(1, 2) = 1;
  if (num_terms_ == 6) {
    gradient(0, 3) = 2 * u.x();
    gradient(0, 4) = u.y();
    gradient(1, 4) = u.x();
    gradient(1, 5) = 2 * u.y();
  }
  return gradient / scale_;
}

std::optional<BoardShading> BoardShading::Fit(const std::vector<Eigen::Vector2d>& corners,
                                              const std::vector<double>& means,
                                              const std::vector<double>& contrasts) {
  const size_t n = corners.size();
  if (n < 6) return std::nullopt;
  BoardShading shading;
  Eigen::Vector2d lo = corners[0], hi = corners[0];
  for (const Eigen::Vector2d& c : corners) {
    shading.centre_ += c / static_cast<double>(n);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  shading.scale_ = std::max(1.0, 0.5 * (hi - lo).maxCoeff());
  shading.num_terms_ = n >= 12 ? 6 : 3;
  Eigen::MatrixXd basis(n, shading.num_terms_);
  Eigen::VectorXd mean(n), log_contrast(n);
  for (size_t i = 0; i < n; ++i) {
    basis.row(i) = shading.Basis(corners[i]).transpose();
    mean[i] = means[i];
    log_contrast[i] = std::log(std::max(contrasts[i], 1e-3));
  }
  shading.mean_ = RobustFit(basis, mean);
  shading.log_contrast_ = RobustFit(basis, log_contrast);
  if (!shading.mean_.allFinite() || !shading.log_contrast_.allFinite()) return std::nullopt;
  return shading;
}

LocalShading BoardShading::At(const Eigen::Vector2d& point) const {
  LocalShading local;
  local.mean = Basis(point).dot(mean_);
  const Eigen::MatrixXd gradient = BasisGradient(point);
  local.mean_gradient = gradient * mean_;
  local.relative_contrast_gradient = gradient * log_contrast_;  // d log c = dc / c
  return local;
}

}  // namespace portcal
