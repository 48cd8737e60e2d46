#include "pipelines/calibration/zhang_initialization.h"

#include <Eigen/Dense>
#include <cmath>

#include "colmap_ext/geometry/hartley_normalization.h"

namespace portcal {
namespace {

// v_ij of Zhang's paper (eq. 8) for columns i, j of H.
Eigen::Matrix<double, 1, 6> V(const Eigen::Matrix3d& h, int i, int j) {
  Eigen::Matrix<double, 1, 6> v;
  v << h(0, i) * h(0, j), h(0, i) * h(1, j) + h(1, i) * h(0, j), h(1, i) * h(1, j),
      h(2, i) * h(0, j) + h(0, i) * h(2, j), h(2, i) * h(1, j) + h(1, i) * h(2, j),
      h(2, i) * h(2, j);
  return v;
}

}  // namespace

std::optional<Eigen::Matrix3d> EstimateHomography(const std::vector<Eigen::Vector2d>& from,
                                                  const std::vector<Eigen::Vector2d>& to) {
  if (from.size() < 4 || from.size() != to.size()) return std::nullopt;
  const Eigen::Matrix3d tf = HartleyNormalization(from), tt = HartleyNormalization(to);
  Eigen::MatrixXd a(2 * from.size(), 9);
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d x = tf * from[i].homogeneous();
    const Eigen::Vector3d y = tt * to[i].homogeneous();
    a.row(2 * i) << x.x(), x.y(), 1, 0, 0, 0, -y.x() * x.x(), -y.x() * x.y(), -y.x();
    a.row(2 * i + 1) << 0, 0, 0, x.x(), x.y(), 1, -y.y() * x.x(), -y.y() * x.y(), -y.y();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Eigen::Matrix3d hn;
  hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  const Eigen::Matrix3d result = tt.inverse() * hn * tf;
  if (!result.allFinite() || std::abs(result(2, 2)) < 1e-15) return std::nullopt;
  return result / result(2, 2);
}

std::optional<Rigid3d> PoseFromNormalizedPlanarView(const PlanarView& view) {
  const auto h = EstimateHomography(view.target_xy, view.pixels);
  if (!h) return std::nullopt;
  // [r1 r2 t] = s H with |r1| = 1 and the target in front (t_z > 0).
  const Eigen::Matrix3d& m = *h;
  double scale = 1.0 / m.col(0).norm();
  if (m(2, 2) * scale < 0) scale = -scale;
  Eigen::Matrix3d r;
  r.col(0) = scale * m.col(0);
  r.col(1) = scale * m.col(1);
  r.col(2) = r.col(0).cross(r.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) rotation = -rotation;
  return Rigid3d(Eigen::Quaterniond(rotation), scale * m.col(2));
}

std::optional<PinholeEstimate> InitializePinholeFromPlanarViews(
    const std::vector<PlanarView>& views, int width, int height) {
  std::vector<Eigen::Matrix3d> homographies;
  for (const PlanarView& view : views) {
    const auto h = EstimateHomography(view.target_xy, view.pixels);
    if (h) homographies.push_back(*h);
  }
  if (homographies.size() < 2) return std::nullopt;
  // B = K^-T K^-1 up to scale; b = (B11, B12, B22, B13, B23, B33); zero skew
  // adds B12 = 0. With fewer than 3 views the principal point is fixed at
  // the image centre (pre-normalizing the pixels by it).
  Eigen::Matrix3d centre = Eigen::Matrix3d::Identity();
  const bool fix_centre = homographies.size() < 3;
  if (fix_centre) {
    centre(0, 2) = -width / 2.0;
    centre(1, 2) = -height / 2.0;
  }
  Eigen::MatrixXd v(2 * homographies.size() + 1 + (fix_centre ? 2 : 0), 6);
  int row = 0;
  for (const Eigen::Matrix3d& h0 : homographies) {
    const Eigen::Matrix3d h = centre * h0;
    v.row(row++) = V(h, 0, 1);
    v.row(row++) = V(h, 0, 0) - V(h, 1, 1);
  }
  v.row(row++) << 0, 1, 0, 0, 0, 0;  // zero skew
  if (fix_centre) {
    v.row(row++) << 0, 0, 0, 1, 0, 0;
    v.row(row++) << 0, 0, 0, 0, 1, 0;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(v, Eigen::ComputeFullV);
  Eigen::VectorXd b = svd.matrixV().col(5);
  if (b(0) < 0) b = -b;
  const double b11 = b(0), b12 = b(1), b22 = b(2), b13 = b(3), b23 = b(4), b33 = b(5);
  // Zhang 2000, Appendix B.
  const double denominator = b11 * b22 - b12 * b12;
  if (!(b11 > 0) || !(denominator > 0)) return std::nullopt;
  const double v0 = (b12 * b13 - b11 * b23) / denominator;
  const double lambda = b33 - (b13 * b13 + v0 * (b12 * b13 - b11 * b23)) / b11;
  if (!(lambda / b11 > 0) || !(lambda * b11 / denominator > 0)) return std::nullopt;
  const double alpha = std::sqrt(lambda / b11);
  const double beta = std::sqrt(lambda * b11 / denominator);
  const double u0 = -b13 * alpha * alpha / lambda;  // zero skew
  PinholeEstimate estimate;
  estimate.fx = alpha;
  estimate.fy = beta;
  estimate.cx = u0 - centre(0, 2);
  estimate.cy = v0 - centre(1, 2);
  if (!std::isfinite(estimate.fx) || !std::isfinite(estimate.fy)) return std::nullopt;
  for (const PlanarView& view : views) {
    PlanarView normalized = view;
    for (Eigen::Vector2d& p : normalized.pixels) {
      p = Eigen::Vector2d((p.x() - estimate.cx) / estimate.fx, (p.y() - estimate.cy) / estimate.fy);
    }
    estimate.cam_from_target.push_back(
        PoseFromNormalizedPlanarView(normalized).value_or(Rigid3d()));
  }
  return estimate;
}

}  // namespace portcal
