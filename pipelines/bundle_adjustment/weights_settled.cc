#include "pipelines/bundle_adjustment/weights_settled.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <utility>

#include "colmap_ext/util/logging.h"

namespace portcal {

WeightsSettledCallback::WeightsSettledCallback(const ceres::Problem* problem,
                                               std::vector<ceres::ResidualBlockId> residual_blocks,
                                               const ceres::LossFunction* loss,
                                               double max_unsettled_fraction)
    : problem_(problem),
      residual_blocks_(std::move(residual_blocks)),
      loss_(loss),
      max_unsettled_fraction_(max_unsettled_fraction) {}

void WeightsSettledCallback::ComputeWeights(std::vector<double>* weights) const {
  weights->assign(residual_blocks_.size(), std::numeric_limits<double>::quiet_NaN());
  // The cost functions themselves, on the parameters' own memory (Problem::
  // EvaluateResidualBlock sets the blocks' state: not from two threads), in
  // two halves on two threads: a survey has millions of blocks.
  const auto evaluate = [&](size_t begin, size_t end) {
    std::vector<double> residuals;
    std::vector<double*> blocks;
    for (size_t i = begin; i < end; ++i) {
      const ceres::ResidualBlockId id = residual_blocks_[i];
      const ceres::CostFunction* cost = problem_->GetCostFunctionForResidualBlock(id);
      problem_->GetParameterBlocksForResidualBlock(id, &blocks);
      residuals.resize(cost->num_residuals());
      if (!cost->Evaluate(blocks.data(), residuals.data(), nullptr)) continue;
      const double squared_norm =
          Eigen::Map<const Eigen::VectorXd>(residuals.data(), residuals.size()).squaredNorm();
      if (!std::isfinite(squared_norm)) continue;
      double rho[3];
      loss_->Evaluate(squared_norm, rho);
      (*weights)[i] = rho[1];
    }
  };
  const size_t half = residual_blocks_.size() / 2;
  std::thread second(evaluate, half, residual_blocks_.size());
  evaluate(0, half);
  second.join();
}

ceres::CallbackReturnType WeightsSettledCallback::operator()(
    const ceres::IterationSummary& summary) {
  if (summary.iteration > 0 && !summary.step_is_successful)
    return ceres::SOLVER_CONTINUE;  // same iterate
  ComputeWeights(&next_weights_);
  const bool first = weights_.empty();
  size_t num_unsettled = 0;
  for (size_t i = 0; !first && i < weights_.size(); ++i) {
    num_unsettled += !(std::abs(next_weights_[i] - weights_[i]) <= kSettledWeightChange);
  }
  weights_.swap(next_weights_);
  if (first) return ceres::SOLVER_CONTINUE;
  last_unsettled_fraction_ =
      static_cast<double>(num_unsettled) / std::max<size_t>(1, weights_.size());
  VLOG(2) << "bundle adjustment: iteration " << summary.iteration << ": " << num_unsettled << " of "
          << weights_.size() << " weights changed by more than " << kSettledWeightChange;
  if (last_unsettled_fraction_ <= max_unsettled_fraction_) {
    VLOG(1) << "bundle adjustment: the robust weights settled after " << summary.iteration
            << " iterations (" << num_unsettled << " of " << weights_.size()
            << " changed by more than " << kSettledWeightChange << ")";
    return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }
  return ceres::SOLVER_CONTINUE;
}

}  // namespace portcal
