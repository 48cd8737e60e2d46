// CRTP base of portcal's cost functors: states the residual and parameter
// block sizes once and builds the Ceres autodiff cost function.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <utility>

namespace portcal {

template <typename Functor, int kNumResiduals, int... kBlockSizes>
struct AutoDiffFunctor {
  static constexpr int kResiduals = kNumResiduals;

  template <typename... Args>
  static ceres::CostFunction* Create(Args&&... args) {
    return new ceres::AutoDiffCostFunction<Functor, kNumResiduals, kBlockSizes...>(
        new Functor(std::forward<Args>(args)...));
  }
};

}  // namespace portcal
