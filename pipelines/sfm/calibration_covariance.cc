#include "pipelines/sfm/calibration_covariance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "colmap_ext/util/error.h"

namespace portcal {

std::vector<double> MarginalCovariance::StdDevs(const double* block) const {
  const int start = offset.at(block);
  std::vector<double> std_dev;
  for (int i = 0; i < size.at(block); ++i) std_dev.push_back(std::sqrt(std::max(0.0, covariance(start + i, start + i))));
  return std_dev;
}

double MarginalCovariance::Correlation(const double* a, int i, const double* b, int j) const {
  const int row = offset.at(a) + i;
  const int col = offset.at(b) + j;
  const double denominator = std::sqrt(covariance(row, row) * covariance(col, col));
  return denominator > 0 ? covariance(row, col) / denominator : 0.0;
}

MarginalCovariance ComputeMarginalCovariance(
    ceres::Problem* problem, const std::vector<double*>& points, const std::vector<double*>& others,
    const std::vector<const double*>& wanted, double scale,
    const std::function<std::string(const double*, int)>& describe) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  evaluate.parameter_blocks = others;
  evaluate.parameter_blocks.insert(evaluate.parameter_blocks.end(), points.begin(), points.end());
  std::map<const double*, int> offset;  // tangent column of each other block
  int nc = 0;
  for (double* block : others) {
    offset[block] = nc;
    nc += problem->ParameterBlockTangentSize(block);
  }
  ceres::CRSMatrix jacobian;
  std::vector<double> residuals;
  if (!problem->Evaluate(evaluate, nullptr, &residuals, nullptr, &jacobian)) {
    throw NumericalError("covariance: the residuals cannot be evaluated at the solution");
  }

  // Accumulate H_cc, and per point H_pp and H_pc (sparse in c).
  Eigen::MatrixXd Hcc = Eigen::MatrixXd::Zero(nc, nc);
  struct PointBlocks {
    Eigen::Matrix3d Hpp = Eigen::Matrix3d::Zero();
    std::unordered_map<int, Eigen::Vector3d> Hpc;  // column -> 3-vector
  };
  std::vector<PointBlocks> point_blocks(points.size());
  std::vector<std::pair<int, double>> camera_entries;
  for (int row = 0; row < jacobian.num_rows; ++row) {
    camera_entries.clear();
    int point = -1;
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (int k = jacobian.rows[row]; k < jacobian.rows[row + 1]; ++k) {
      const int col = jacobian.cols[k];
      const double value = jacobian.values[k];
      if (col < nc) {
        camera_entries.emplace_back(col, value);
      } else {
        const int p = (col - nc) / 3;
        PORTCAL_CHECK_MSG(point == -1 || point == p, "a residual touches two marginalised points");
        point = p;
        b((col - nc) % 3) = value;
      }
    }
    for (const auto& [i, vi] : camera_entries) {
      for (const auto& [j, vj] : camera_entries) Hcc(i, j) += vi * vj;
    }
    if (point < 0) continue;
    PointBlocks& pb = point_blocks[static_cast<size_t>(point)];
    pb.Hpp += b * b.transpose();
    for (const auto& [i, vi] : camera_entries) {
      auto it = pb.Hpc.find(i);
      if (it == pb.Hpc.end()) it = pb.Hpc.emplace(i, Eigen::Vector3d::Zero()).first;
      it->second += b * vi;
    }
  }
  // Schur complement S = Hcc - sum_p Hcp Hpp^+ Hpc.
  for (const PointBlocks& pb : point_blocks) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(pb.Hpp);
    const Eigen::Vector3d values = eig.eigenvalues();
    Eigen::Vector3d inverse = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      if (values(k) > 1e-12 * values(2)) inverse(k) = 1.0 / values(k);
    }
    const Eigen::Matrix3d Hpp_pinv = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
    for (const auto& [i, hi] : pb.Hpc) {
      const Eigen::Vector3d w = Hpp_pinv * hi;
      for (const auto& [j, hj] : pb.Hpc) Hcc(i, j) -= w.dot(hj);
    }
  }
  // Jacobi scaling: rotations (radians), translations (metres), focal
  // lengths (pixels) and distortion differ by many orders of magnitude in
  // their information; the rank test and the inverse work on the scaled
  // system S' = D^-1/2 S D^-1/2 (D = diag S), whose diagonal is 1.
  Eigen::VectorXd d_inv_sqrt(nc);
  for (int i = 0; i < nc; ++i) d_inv_sqrt(i) = Hcc(i, i) > 0 ? 1.0 / std::sqrt(Hcc(i, i)) : 0.0;
  const Eigen::MatrixXd scaled = d_inv_sqrt.asDiagonal() * (0.5 * (Hcc + Hcc.transpose())) * d_inv_sqrt.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  const Eigen::VectorXd values = eig.eigenvalues();
  if (nc == 0) throw NumericalError("covariance: no free parameters");
  if (!(values(0) > 1e-12 * values(nc - 1))) {
    Eigen::Index column;
    eig.eigenvectors().col(0).cwiseAbs().maxCoeff(&column);
    std::string name = "parameter " + std::to_string(column);
    for (const auto& [block, start] : offset) {
      const int size = problem->ParameterBlockTangentSize(block);
      if (column >= start && column < start + size) name = describe(block, static_cast<int>(column) - start) + " [tangent " + std::to_string(column - start) + "]";
    }
    std::ostringstream ratio;
    ratio << values(0) / values(nc - 1);
    throw NumericalError("covariance: the views do not determine " + name +
                         " (reduced system rank deficient: eigenvalue ratio " + ratio.str() +
                         "); hold it fixed or add views");
  }
  const Eigen::MatrixXd covariance = d_inv_sqrt.asDiagonal() * eig.eigenvectors() *
                                     values.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose() *
                                     d_inv_sqrt.asDiagonal();

  // Each wanted block's tangent covariance mapped to its ambient
  // coordinates by the manifold's plus Jacobian: C_ab = P_a C'_ab P_b^T.
  MarginalCovariance result;
  std::vector<Eigen::MatrixXd> plus;
  int total = 0;
  for (const double* block : wanted) {
    const int tangent = problem->ParameterBlockTangentSize(block);
    const int ambient = problem->ParameterBlockSize(block);
    Eigen::MatrixXd p = Eigen::MatrixXd::Identity(ambient, tangent);
    if (const ceres::Manifold* manifold = problem->GetManifold(block)) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(ambient, tangent);
      manifold->PlusJacobian(block, J.data());
      p = J;
    }
    plus.push_back(p);
    result.offset[block] = total;
    result.size[block] = ambient;
    total += ambient;
  }
  result.covariance = Eigen::MatrixXd::Zero(total, total);
  for (size_t a = 0; a < wanted.size(); ++a) {
    const int ta = offset.at(const_cast<double*>(wanted[a]));
    for (size_t b = 0; b < wanted.size(); ++b) {
      const int tb = offset.at(const_cast<double*>(wanted[b]));
      result.covariance.block(result.offset[wanted[a]], result.offset[wanted[b]], plus[a].rows(), plus[b].rows()) =
          scale * scale * plus[a] * covariance.block(ta, tb, plus[a].cols(), plus[b].cols()) * plus[b].transpose();
    }
  }
  return result;
}

}  // namespace portcal
