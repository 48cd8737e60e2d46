// An end for a robust solve whose only task is to decide the robust loss's
// weights for a solve that then holds them (IRLS's "decide the inliers,
// then solve least squares"; BundleAdjustmentOptions::hold_loss_weights).
// Ceres' relative cost change is the wrong measure of that: on a survey the
// Cauchy loss's reweighting moves the cost by a few 1e-6 of itself per
// iteration for many iterations, more of them the longer the survey
// (docs/scale.md), while the weights stopped changing after the first.
#pragma once

#include <ceres/ceres.h>

#include <vector>

namespace portcal {

// Ends the solve (SOLVER_TERMINATE_SUCCESSFULLY) once an accepted step has
// changed the weight rho'(|r|^2) (in (0, 1]) of at most a given fraction of
// the residual blocks by more than kSettledWeightChange: the inliers are
// decided. A fraction, not all of them: through the reweighting's crawl a
// few dozen observations on the loss's slope keep moving by 0.05-0.2 while
// the rest are still (docs/scale.md). Needs the solver's
// update_state_every_iteration, so that the parameter blocks hold the
// current iterate when it is called.
class WeightsSettledCallback : public ceres::IterationCallback {
 public:
  // `residual_blocks`: those under `loss` (the problem owns both).
  WeightsSettledCallback(const ceres::Problem* problem,
                         std::vector<ceres::ResidualBlockId> residual_blocks,
                         const ceres::LossFunction* loss, double max_unsettled_fraction);
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;

  static constexpr double kSettledWeightChange = 0.01;

  // Of the last accepted step, the fraction of blocks whose weight changed
  // by more than kSettledWeightChange (-1 before one).
  double last_unsettled_fraction() const { return last_unsettled_fraction_; }

 private:
  // The weights at the current parameters; NaN where a block cannot be
  // evaluated (its weight then never counts as settled).
  void ComputeWeights(std::vector<double>* weights) const;

  const ceres::Problem* problem_;
  std::vector<ceres::ResidualBlockId> residual_blocks_;
  const ceres::LossFunction* loss_;
  double max_unsettled_fraction_;
  std::vector<double> weights_, next_weights_;
  double last_unsettled_fraction_ = -1;
};

}  // namespace portcal
