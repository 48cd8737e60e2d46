// A bundle's Gauss-Newton system J'J reduced over its 3-D points, built one
// point at a time from the residual blocks' own Jacobians: the reduced
// matrix S = H_cc - H_cp H_pp^+ H_pc on the other blocks' tangent columns,
// and each residual's reduced gradient. Nothing of the size of the whole
// Jacobian is held -- a survey's Jacobian (20 values per observation)
// would outweigh the problem itself -- only S, sparse (two images couple
// only through the points both see), and a list of residual blocks per
// point.
#pragma once
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Sparse>
#include <cstdint>
#include <functional>
#include <map>
#include <unordered_map>
#include <vector>

namespace portcal {

class PointSchurComplement {
 public:
  // `points`: 3-parameter blocks to marginalise (a residual block may touch
  // at most one); `others`: the other variable blocks, whose tangent
  // columns are S's, in this order. Blocks in neither list are taken as
  // held. The points are shared among `num_threads` threads. Throws
  // NumericalError when a residual cannot be evaluated.
  PointSchurComplement(ceres::Problem* problem, const std::vector<double*>& points,
                       const std::vector<double*>& others, int num_threads = 1);

  int num_columns() const { return num_columns_; }
  // Tangent column of each other block's first coordinate.
  const std::map<const double*, int>& offset() const { return offset_; }
  // Every residual block of the problem, in the problem's order.
  const std::vector<ceres::ResidualBlockId>& residual_blocks() const { return residual_blocks_; }
  // |r|^2 of each residual block, without its loss function.
  const std::vector<double>& squared_norms() const { return squared_norms_; }
  // S, symmetric, num_columns x num_columns.
  const Eigen::SparseMatrix<double>& reduced() const { return reduced_; }

  // For each residual block k (index into residual_blocks()): gain *
  // (J_c' - H_cp H_pp^+ J_p') weights[k] r_k, its weighted gradient with
  // the points' response removed, mapped by `gain` (rows x num_columns).
  // Computed on the threads, visited on the caller's, in point order.
  void VisitReducedGradients(
      const Eigen::MatrixXd& gain, const std::vector<double>& weights,
      const std::function<void(size_t, const Eigen::VectorXd&)>& visit) const;

 private:
  struct Linearised;
  struct PointBlocks;
  // Blocks of S by pairs of other blocks (a <= b, key a << 32 | b).
  using PairBlocks = std::unordered_map<uint64_t, Eigen::MatrixXd>;

  void IndexBlocks(const std::vector<double*>& points, const std::vector<double*>& others);
  void GroupByPoint(size_t num_points);
  void Assemble(const PairBlocks& pairs);
  void Linearise(size_t block, Linearised* out) const;
  void AccumulatePoint(size_t point, std::vector<Linearised>* linearised, PointBlocks* local) const;
  void Reduce(size_t point, std::vector<Linearised>* linearised, PairBlocks* pairs);
  void ReducedGradientsOf(size_t point, const Eigen::MatrixXd& gain,
                          const std::vector<double>& weights,
                          std::vector<Linearised>* linearised_scratch,
                          std::vector<std::pair<size_t, Eigen::VectorXd>>* out) const;

  ceres::Problem* problem_;
  int num_threads_ = 1;
  std::unordered_map<const double*, int> point_index_;
  std::unordered_map<const double*, int> other_index_;
  std::vector<int> start_, size_;      // each other block's tangent columns
  std::vector<Eigen::MatrixXd> plus_;  // its plus Jacobian (empty: identity)
  std::map<const double*, int> offset_;
  int num_columns_ = 0;
  std::vector<ceres::ResidualBlockId> residual_blocks_;
  std::vector<double> squared_norms_;
  // Residual blocks of point p: by_point_[first_[p] .. first_[p + 1]); the
  // blocks of no point after first_[num_points].
  std::vector<size_t> first_, by_point_;
  Eigen::SparseMatrix<double> reduced_;
};

}  // namespace portcal
