#include "pipelines/sfm/calibration_covariance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "colmap_ext/util/error.h"

namespace portcal {

namespace {

// Square roots of a diagonal stretch, negatives (round-off) as 0.
std::vector<double> DiagonalStdDevs(const Eigen::MatrixXd& covariance, int start, int size) {
  std::vector<double> std_dev;
  for (int i = 0; i < size; ++i) std_dev.push_back(std::sqrt(std::max(0.0, covariance(start + i, start + i))));
  return std_dev;
}

}  // namespace

std::vector<double> MarginalCovariance::StdDevs(const double* block) const {
  return DiagonalStdDevs(covariance, offset.at(block), size.at(block));
}

std::vector<double> MarginalCovariance::ClusteredStdDevs(const double* block) const {
  if (clustered_covariance.size() == 0) return {};
  return DiagonalStdDevs(clustered_covariance, offset.at(block), size.at(block));
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
    const std::function<std::string(const double*, int)>& describe, const ResidualClusters* clusters) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  evaluate.parameter_blocks = others;
  evaluate.parameter_blocks.insert(evaluate.parameter_blocks.end(), points.begin(), points.end());
  problem->GetResidualBlocks(&evaluate.residual_blocks);
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
  // Each row's cluster, and the weight of its gradient: the loss's
  // derivative rho'(|r|^2) of its block (at the solution the robust
  // gradient, rho' J'r, is what balances).
  std::vector<int> row_cluster;
  std::vector<double> row_weight;
  int num_clusters = 0;
  if (clusters) {
    std::map<int, int> index_of_cluster;
    int next_own = -1;  // blocks in no listed cluster: each its own
    std::vector<double*> blocks;
    for (const ceres::ResidualBlockId id : evaluate.residual_blocks) {
      problem->GetParameterBlocksForResidualBlock(id, &blocks);
      int cluster = next_own--;
      for (double* block : blocks) {
        const auto it = clusters->cluster_of_block.find(block);
        if (it != clusters->cluster_of_block.end()) {
          cluster = it->second;
          break;
        }
      }
      auto [it, inserted] = index_of_cluster.emplace(cluster, num_clusters);
      if (inserted) ++num_clusters;
      const int rows = problem->GetCostFunctionForResidualBlock(id)->num_residuals();
      double squared_norm = 0;
      for (int k = 0; k < rows; ++k) squared_norm += residuals[row_cluster.size() + k] * residuals[row_cluster.size() + k];
      double rho[3] = {squared_norm, 1, 0};
      if (const ceres::LossFunction* loss = problem->GetLossFunctionForResidualBlock(id)) loss->Evaluate(squared_norm, rho);
      row_cluster.insert(row_cluster.end(), rows, it->second);
      row_weight.insert(row_weight.end(), rows, rho[1]);
    }
    PORTCAL_CHECK_MSG(static_cast<int>(row_cluster.size()) == jacobian.num_rows, "residual rows and blocks disagree");
  }
  // Reduced gradient of each cluster's residuals: u_k = g_c,k - H_cp
  // H_pp^+ g_p,k (the points' share removed as in the Schur complement).
  Eigen::MatrixXd cluster_gradients = Eigen::MatrixXd::Zero(clusters ? nc : 0, num_clusters);

  // Accumulate H_cc, and per point H_pp and H_pc (sparse in c).
  Eigen::MatrixXd Hcc = Eigen::MatrixXd::Zero(nc, nc);
  struct PointBlocks {
    Eigen::Matrix3d Hpp = Eigen::Matrix3d::Zero();
    std::unordered_map<int, Eigen::Vector3d> Hpc;       // column -> 3-vector
    std::unordered_map<int, Eigen::Vector3d> gradient;  // cluster -> its residuals' g_p
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
    const double weighted_residual = clusters ? row_weight[row] * residuals[row] : 0.0;
    if (clusters) {
      for (const auto& [i, vi] : camera_entries) cluster_gradients(i, row_cluster[row]) += vi * weighted_residual;
    }
    if (point < 0) continue;
    PointBlocks& pb = point_blocks[static_cast<size_t>(point)];
    pb.Hpp += b * b.transpose();
    if (clusters) {
      auto it = pb.gradient.find(row_cluster[row]);
      if (it == pb.gradient.end()) it = pb.gradient.emplace(row_cluster[row], Eigen::Vector3d::Zero()).first;
      it->second += b * weighted_residual;
    }
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
    for (const auto& [k, g] : pb.gradient) {
      const Eigen::Vector3d w = Hpp_pinv * g;
      for (const auto& [i, hi] : pb.Hpc) cluster_gradients(i, k) -= hi.dot(w);
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
  if (clusters && num_clusters > 1) {
    // Each cluster's linearised effect on the wanted blocks, S^-1 u_k, in
    // ambient coordinates; their outer products summed, with the small-
    // sample factors: G / (G - 1) (the "CR1" correction for few clusters)
    // and N / (N - K) for the share of the residuals' spread the fitted
    // parameters absorbed (as the model covariance's sigma0^2 has).
    Eigen::MatrixXd effects(total, num_clusters);
    for (size_t a = 0; a < wanted.size(); ++a) {
      const int ta = offset.at(const_cast<double*>(wanted[a]));
      effects.middleRows(result.offset[wanted[a]], plus[a].rows()) =
          plus[a] * (covariance.middleRows(ta, plus[a].cols()) * cluster_gradients);
    }
    const double factor = num_clusters / (num_clusters - 1.0) * clusters->residuals_per_dof;
    result.clustered_covariance = factor * effects * effects.transpose();
    result.num_clusters = num_clusters;
  }
  return result;
}

}  // namespace portcal
