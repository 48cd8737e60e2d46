#include "pipelines/bundle_adjustment/calibration_covariance.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/point_schur.h"

namespace portcal {

namespace {

// Square roots of a diagonal stretch, negatives (round-off) as 0.
std::vector<double> DiagonalStdDevs(const Eigen::MatrixXd& covariance, int start, int size) {
  std::vector<double> std_dev;
  for (int i = 0; i < size; ++i)
    std_dev.push_back(std::sqrt(std::max(0.0, covariance(start + i, start + i))));
  return std_dev;
}

// A residual block's place in the clusterings.
struct BlockClusters {
  int image = 0;   // its image cluster
  int track = -1;  // its track cluster (-1: clustered by image only)
  int both = -1;   // its (image, track) cluster
  int rows = 0;
  double weight = 1;  // rho'(|r|^2) of the block's loss
};

// Dense cluster indices of every residual block (see ResidualClusters).
std::vector<BlockClusters> AssignClusters(ceres::Problem* problem,
                                          const std::vector<ceres::ResidualBlockId>& ids,
                                          const std::vector<double*>& points,
                                          const std::vector<double>& squared_norms,
                                          const ResidualClusters& clusters) {
  std::unordered_map<const double*, int> point_index;
  for (size_t p = 0; p < points.size(); ++p) point_index[points[p]] = static_cast<int>(p);
  // Listed clusters by their given id, points by index; the rest their own.
  std::map<int, int> image_index, listed_track_index;
  std::unordered_map<int, int> point_track_index;
  std::unordered_map<int64_t, int> both_index;
  int num_images = 0, num_tracks = 0, num_both = 0;
  const auto dense = [](auto& index, auto key, int* count) {
    const auto [it, inserted] = index.emplace(key, *count);
    if (inserted) ++*count;
    return it->second;
  };
  std::vector<BlockClusters> result;
  std::vector<double*> blocks;
  for (size_t k = 0; k < ids.size(); ++k) {
    const ceres::ResidualBlockId id = ids[k];
    problem->GetParameterBlocksForResidualBlock(id, &blocks);
    BlockClusters b;
    b.image = -1;
    for (double* block : blocks) {
      const auto it = clusters.image_of_block.find(block);
      if (it != clusters.image_of_block.end()) {
        b.image = dense(image_index, it->second, &num_images);
        break;
      }
    }
    if (b.image < 0) b.image = num_images++;
    if (clusters.by_track) {
      for (double* block : blocks) {
        if (const auto it = point_index.find(block); it != point_index.end()) {
          b.track = dense(point_track_index, it->second, &num_tracks);
          break;
        }
      }
      for (double* block : blocks) {
        if (b.track >= 0) break;
        if (const auto it = clusters.track_of_block.find(block);
            it != clusters.track_of_block.end()) {
          b.track = dense(listed_track_index, it->second, &num_tracks);
        }
      }
      if (b.track < 0) b.track = num_tracks++;
      const int64_t key = (static_cast<int64_t>(b.image) << 32) | static_cast<uint32_t>(b.track);
      b.both = dense(both_index, key, &num_both);
    }
    b.rows = problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    double rho[3] = {squared_norms[k], 1, 0};
    if (const ceres::LossFunction* loss = problem->GetLossFunctionForResidualBlock(id)) {
      loss->Evaluate(squared_norms[k], rho);
    }
    b.weight = rho[1];
    result.push_back(b);
  }
  return result;
}

// The clusters' summed effects and, from them, the two-way covariance.
class ClusterEffects {
 public:
  ClusterEffects(int size, const std::vector<BlockClusters>& blocks)
      : blocks_(blocks), both_(size, size) {
    int num_images = 0, num_tracks = 0;
    std::unordered_map<int, int> blocks_of_both;
    for (const BlockClusters& b : blocks) {
      num_images = std::max(num_images, b.image + 1);
      num_tracks = std::max(num_tracks, b.track + 1);
      if (b.both >= 0) ++blocks_of_both[b.both];
    }
    images_ = Eigen::MatrixXd::Zero(size, num_images);
    tracks_ = Eigen::MatrixXd::Zero(size, num_tracks);
    both_.setZero();
    num_both_ = static_cast<int>(blocks_of_both.size());
    // An (image, track) pair is nearly always one residual block: its
    // outer product is taken at once, the few others are summed first.
    for (const auto& [both, count] : blocks_of_both) {
      if (count > 1) shared_both_.emplace(both, Eigen::VectorXd::Zero(size));
    }
  }

  void Add(size_t block, const Eigen::VectorXd& effect) {
    const BlockClusters& b = blocks_[block];
    images_.col(b.image) += effect;
    if (b.track < 0) return;
    tracks_.col(b.track) += effect;
    if (const auto it = shared_both_.find(b.both); it != shared_both_.end()) {
      it->second += effect;
    } else {
      both_.noalias() += effect * effect.transpose();
    }
  }

  // V_image (+ V_track - V_both), each the sum of its clusters' outer
  // products times the small-sample factors G / (G - 1) (the "CR1"
  // correction for few clusters) and N / (N - K) (the share of the
  // residuals' spread the fitted parameters absorbed, as the model
  // covariance's sigma0^2 has); empty with fewer than two images. Negative
  // eigenvalues of the two-way sum (possible in finite samples) are set to
  // zero, as Cameron, Gelbach & Miller propose.
  Eigen::MatrixXd Covariance(double residuals_per_dof, int* num_images, int* num_tracks) const {
    const auto factor = [&](Eigen::Index g) { return g / (g - 1.0) * residuals_per_dof; };
    *num_images = static_cast<int>(images_.cols());
    if (images_.cols() < 2) return {};
    Eigen::MatrixXd covariance = factor(images_.cols()) * images_ * images_.transpose();
    if (tracks_.cols() < 2 || num_both_ < 2) return covariance;
    *num_tracks = static_cast<int>(tracks_.cols());
    Eigen::MatrixXd both = both_;
    for (const auto& [index, effect] : shared_both_) both.noalias() += effect * effect.transpose();
    covariance += factor(tracks_.cols()) * tracks_ * tracks_.transpose() - factor(num_both_) * both;
    // Clipped on the coordinates that vary: held ones stay exactly zero.
    std::vector<Eigen::Index> varying;
    for (Eigen::Index i = 0; i < covariance.rows(); ++i) {
      if (images_.row(i).any() || tracks_.row(i).any()) varying.push_back(i);
    }
    Eigen::MatrixXd sub(varying.size(), varying.size());
    for (size_t i = 0; i < varying.size(); ++i) {
      for (size_t j = 0; j < varying.size(); ++j) sub(i, j) = covariance(varying[i], varying[j]);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (sub + sub.transpose()));
    sub = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
          eig.eigenvectors().transpose();
    covariance.setZero();
    for (size_t i = 0; i < varying.size(); ++i) {
      for (size_t j = 0; j < varying.size(); ++j) covariance(varying[i], varying[j]) = sub(i, j);
    }
    return covariance;
  }

 private:
  const std::vector<BlockClusters>& blocks_;
  Eigen::MatrixXd images_, tracks_;  // summed effect of each cluster
  Eigen::MatrixXd both_;             // sum of the (image, track) clusters' outer products
  int num_both_ = 0;
  std::unordered_map<int, Eigen::VectorXd> shared_both_;
};

// The error for a singular reduced system; `measure` says which ratio
// (smallest to largest eigenvalue, or pivot) showed it.
NumericalError RankDeficient(const std::string& name, const char* measure, double ratio) {
  std::ostringstream text;
  text << ratio;
  return NumericalError("covariance: the views do not determine " + name +
                        " (reduced system rank deficient: " + measure + " ratio " + text.str() +
                        "); hold it fixed or add views");
}

// Rows of S^-1 at `wanted` by a dense eigen-decomposition of the scaled
// system, whose smallest eigenvector names the parameter that dominates an
// unobservable direction.
Eigen::MatrixXd DenseInverseRows(const Eigen::SparseMatrix<double>& reduced,
                                 const Eigen::VectorXd& d_inv_sqrt, const std::vector<int>& wanted,
                                 const std::function<std::string(Eigen::Index)>& name_of) {
  const Eigen::MatrixXd s = Eigen::MatrixXd(reduced);
  const Eigen::MatrixXd scaled =
      d_inv_sqrt.asDiagonal() * (0.5 * (s + s.transpose())) * d_inv_sqrt.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  const Eigen::VectorXd values = eig.eigenvalues();
  const Eigen::Index n = values.size();
  if (!(values(0) > 1e-12 * values(n - 1))) {
    Eigen::Index column;
    eig.eigenvectors().col(0).cwiseAbs().maxCoeff(&column);
    throw RankDeficient(name_of(column), "eigenvalue", values(0) / values(n - 1));
  }
  Eigen::MatrixXd rows(wanted.size(), n);
  for (size_t k = 0; k < wanted.size(); ++k) {
    rows.row(static_cast<Eigen::Index>(k)) =
        (eig.eigenvectors().row(wanted[k]) * values.cwiseInverse().asDiagonal() *
         eig.eigenvectors().transpose())
            .cwiseProduct(d_inv_sqrt.transpose()) *
        d_inv_sqrt(wanted[k]);
  }
  return rows;
}

// The same by a sparse LDL' factorisation of the scaled system (fill-
// reducing AMD order): a survey's S couples each image with its
// neighbours only, and its dense decomposition costs n^3. Rank deficiency
// shows as a vanishing pivot; the parameter at that pivot is named.
Eigen::MatrixXd SparseInverseRows(const Eigen::SparseMatrix<double>& reduced,
                                  const Eigen::VectorXd& d_inv_sqrt, const std::vector<int>& wanted,
                                  const std::function<std::string(Eigen::Index)>& name_of) {
  const Eigen::SparseMatrix<double> symmetric =
      0.5 * (reduced + Eigen::SparseMatrix<double>(reduced.transpose()));
  const Eigen::SparseMatrix<double> scaled =
      d_inv_sqrt.asDiagonal() * symmetric * d_inv_sqrt.asDiagonal();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(scaled);
  if (ldlt.info() != Eigen::Success) {
    // An exactly zero pivot stops the factorisation where it is; a shift
    // far below the rank test's threshold lets it finish so that the
    // pivot can be found and named (the shifted factor gives no numbers).
    ldlt.setShift(1e-15);
    ldlt.factorize(scaled);
    if (ldlt.info() != Eigen::Success)
      throw NumericalError("covariance: the reduced system cannot be factorised");
  }
  const Eigen::VectorXd pivots = ldlt.vectorD();
  Eigen::Index smallest;
  const double ratio = pivots.minCoeff(&smallest) / pivots.cwiseAbs().maxCoeff();
  if (!(ratio > 1e-12))
    throw RankDeficient(name_of(ldlt.permutationPinv().indices()(smallest)), "pivot", ratio);
  Eigen::MatrixXd unit =
      Eigen::MatrixXd::Zero(scaled.rows(), static_cast<Eigen::Index>(wanted.size()));
  for (size_t k = 0; k < wanted.size(); ++k)
    unit(wanted[k], static_cast<Eigen::Index>(k)) = d_inv_sqrt(wanted[k]);
  const Eigen::MatrixXd solved = ldlt.solve(unit);
  return (d_inv_sqrt.asDiagonal() * solved).transpose();
}

// Jacobi scaling: rotations (radians), translations (metres), focal
// lengths (pixels) and distortion differ by many orders of magnitude in
// their information; the rank test and the inverse work on the scaled
// system S' = D^-1/2 S D^-1/2 (D = diag S), whose diagonal is 1.
Eigen::VectorXd JacobiScaling(const Eigen::SparseMatrix<double>& reduced, int num_columns) {
  Eigen::VectorXd d_inv_sqrt(num_columns);
  for (int i = 0; i < num_columns; ++i) {
    const double d = reduced.coeff(i, i);
    d_inv_sqrt(i) = d > 0 ? 1.0 / std::sqrt(d) : 0.0;
  }
  return d_inv_sqrt;
}

// Each wanted block's plus Jacobian (tangent to ambient coordinates), its
// rows in the result, and its tangent coordinates in the reduced system.
struct WantedTangents {
  std::vector<Eigen::MatrixXd> plus;
  std::vector<int> columns;  // in order; block a's start at first_row[a]
  std::vector<int> first_row;
  int total = 0;  // ambient coordinates of all wanted blocks
};

WantedTangents TangentsOf(ceres::Problem* problem, const std::vector<const double*>& wanted,
                          const std::map<const double*, int>& offset, MarginalCovariance* result) {
  WantedTangents out;
  for (const double* block : wanted) {
    const int tangent = problem->ParameterBlockTangentSize(block);
    const int ambient = problem->ParameterBlockSize(block);
    Eigen::MatrixXd p = Eigen::MatrixXd::Identity(ambient, tangent);
    if (const ceres::Manifold* manifold = problem->GetManifold(block)) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J(ambient, tangent);
      manifold->PlusJacobian(block, J.data());
      p = J;
    }
    out.plus.push_back(p);
    out.first_row.push_back(static_cast<int>(out.columns.size()));
    const int start = offset.at(block);
    for (int k = 0; k < tangent; ++k) out.columns.push_back(start + k);
    result->offset[block] = out.total;
    result->size[block] = ambient;
    out.total += ambient;
  }
  return out;
}

// Each residual's linearised effect on the wanted blocks (ambient
// coordinates): the gain S^-1 (wanted rows) applied to its reduced
// gradient w r (J_c' - H_cp H_pp^+ J_p'), w = rho' -- the points' share
// removed as in the Schur complement. A cluster's effect S^-1 u_k is the
// sum of its residuals' effects.
Eigen::MatrixXd ClusteredCovariance(const PointSchurComplement& schur,
                                    const std::vector<const double*>& wanted,
                                    const WantedTangents& tangents,
                                    const Eigen::MatrixXd& inverse_rows,
                                    const std::vector<BlockClusters>& block_clusters,
                                    const ResidualClusters& clusters, MarginalCovariance* result) {
  Eigen::MatrixXd gain(tangents.total, schur.num_columns());
  for (size_t a = 0; a < wanted.size(); ++a) {
    gain.middleRows(result->offset[wanted[a]], tangents.plus[a].rows()) =
        tangents.plus[a] * inverse_rows.middleRows(tangents.first_row[a], tangents.plus[a].cols());
  }
  std::vector<double> weights;
  weights.reserve(block_clusters.size());
  for (const BlockClusters& b : block_clusters) weights.push_back(b.weight);
  ClusterEffects effects(tangents.total, block_clusters);
  schur.VisitReducedGradients(gain, weights, [&](size_t block, const Eigen::VectorXd& effect) {
    effects.Add(block, effect);
  });
  return effects.Covariance(clusters.residuals_per_dof, &result->num_clusters, &result->num_tracks);
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
    const std::function<std::string(const double*, int)>& describe,
    const ResidualClusters* clusters, int max_dense_size, int num_threads) {
  const PointSchurComplement schur(problem, points, others, num_threads);
  const int nc = schur.num_columns();
  // Each residual block's clusters and the weight of its gradient: the
  // loss's derivative rho'(|r|^2) (at the solution the robust gradient,
  // rho' J'r, is what balances).
  std::vector<BlockClusters> block_clusters;
  if (clusters) {
    block_clusters =
        AssignClusters(problem, schur.residual_blocks(), points, schur.squared_norms(), *clusters);
  }
  const Eigen::VectorXd d_inv_sqrt = JacobiScaling(schur.reduced(), nc);
  const auto name_of = [&](Eigen::Index column) {
    for (const auto& [block, start] : schur.offset()) {
      const int size = problem->ParameterBlockTangentSize(block);
      if (column >= start && column < start + size) {
        return describe(block, static_cast<int>(column) - start) + " [tangent " +
               std::to_string(column - start) + "]";
      }
    }
    return "parameter " + std::to_string(column);
  };
  MarginalCovariance result;
  const WantedTangents tangents = TangentsOf(problem, wanted, schur.offset(), &result);
  // The rows of S^-1 at the wanted coordinates.
  const Eigen::MatrixXd inverse_rows =
      nc <= max_dense_size
          ? DenseInverseRows(schur.reduced(), d_inv_sqrt, tangents.columns, name_of)
          : SparseInverseRows(schur.reduced(), d_inv_sqrt, tangents.columns, name_of);

  // Each wanted block's tangent covariance mapped to its ambient
  // coordinates: C_ab = P_a C'_ab P_b^T.
  result.covariance = Eigen::MatrixXd::Zero(tangents.total, tangents.total);
  for (size_t a = 0; a < wanted.size(); ++a) {
    for (size_t b = 0; b < wanted.size(); ++b) {
      const Eigen::MatrixXd& pa = tangents.plus[a];
      const Eigen::MatrixXd& pb = tangents.plus[b];
      const int tb = schur.offset().at(wanted[b]);
      result.covariance.block(result.offset[wanted[a]], result.offset[wanted[b]], pa.rows(),
                              pb.rows()) =
          scale * scale * pa * inverse_rows.block(tangents.first_row[a], tb, pa.cols(), pb.cols()) *
          pb.transpose();
    }
  }
  if (clusters) {
    result.clustered_covariance = ClusteredCovariance(schur, wanted, tangents, inverse_rows,
                                                      block_clusters, *clusters, &result);
  }
  return result;
}

}  // namespace portcal
