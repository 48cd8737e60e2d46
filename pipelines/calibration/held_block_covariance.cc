#include "pipelines/calibration/held_block_covariance.h"

#include <ceres/crs_matrix.h>
#include <ceres/manifold.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <vector>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

Eigen::MatrixXd Dense(const ceres::CRSMatrix& crs) {
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) dense(r, crs.cols[k]) = crs.values[k];
  }
  return dense;
}

// Keeps a block variable while it lives, constant again after.
class Freed {
 public:
  Freed(ceres::Problem* problem, double* block) : problem_(problem), block_(block) {
    problem_->SetParameterBlockVariable(block_);
  }
  ~Freed() { problem_->SetParameterBlockConstant(block_); }
  Freed(const Freed&) = delete;
  Freed& operator=(const Freed&) = delete;

 private:
  ceres::Problem* problem_;
  double* block_;
};

}  // namespace

Eigen::MatrixXd HeldBlockCovarianceContribution(ceres::Problem* problem, double* held,
                                                const Eigen::MatrixXd& held_covariance,
                                                double* of) {
  PORTCAL_CHECK(problem->IsParameterBlockConstant(held) && !problem->IsParameterBlockConstant(of));
  const int held_size = problem->ParameterBlockSize(held);
  PORTCAL_CHECK(held_covariance.rows() == held_size && held_covariance.cols() == held_size);
  std::vector<double*> blocks;
  problem->GetParameterBlocks(&blocks);
  ceres::Problem::EvaluateOptions options;
  int of_column = -1, column = 0;
  for (double* block : blocks) {
    if (block == held || problem->IsParameterBlockConstant(block)) continue;
    if (block == of) of_column = column;
    options.parameter_blocks.push_back(block);
    column += problem->ParameterBlockTangentSize(block);
  }
  const int free_columns = column;
  options.parameter_blocks.push_back(held);
  ceres::CRSMatrix crs;
  {
    const Freed freed(problem, held);  // without a manifold: the held block's ambient columns
    if (!problem->Evaluate(options, nullptr, nullptr, nullptr, &crs)) {
      throw NumericalError(
          "propagating the held parameters' covariance: the Jacobian could not be evaluated");
    }
  }
  const Eigen::MatrixXd jacobian = Dense(crs);
  const Eigen::MatrixXd free_part = jacobian.leftCols(free_columns);
  const Eigen::LDLT<Eigen::MatrixXd> information(free_part.transpose() * free_part);
  if (information.info() != Eigen::Success || !(information.vectorD().minCoeff() > 0)) {
    throw NumericalError(
        "propagating the held parameters' covariance: the free parameters are undetermined");
  }
  // dx/dtheta, the rows of `of` only.
  const int of_size = problem->ParameterBlockTangentSize(of);
  const Eigen::MatrixXd sensitivity =
      -information.solve(free_part.transpose() * jacobian.rightCols(held_size))
           .middleRows(of_column, of_size);
  const Eigen::MatrixXd tangent = sensitivity * held_covariance * sensitivity.transpose();
  const ceres::Manifold* manifold = problem->GetManifold(of);
  if (manifold == nullptr) return 0.5 * (tangent + tangent.transpose());
  const int ambient = problem->ParameterBlockSize(of);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> plus(ambient, of_size);
  if (!manifold->PlusJacobian(of, plus.data())) {
    throw NumericalError("propagating the held parameters' covariance: no Plus Jacobian");
  }
  const Eigen::MatrixXd result = plus * tangent * plus.transpose();
  return 0.5 * (result + result.transpose());
}

}  // namespace portcal
