// The residual blocks of a problem that cannot be evaluated, with their
// Jacobians, at the parameters' current values. Ceres reports such a block
// at a solve's start only as "Residual and Jacobian evaluation failed",
// without saying which; the bundle adjustment names them (and the mapper
// drops their observations before a global adjustment, see
// incremental_mapper.cc).
#pragma once

#include <ceres/ceres.h>

#include <functional>
#include <string>
#include <vector>

namespace portcal {

// Evaluates each residual block's cost function directly (every parameter
// block's Jacobian, constant or not, in the ambient space), so that both
// the value path and the autodiff (Jet) path are tried: with exact
// refraction they can fail apart (port_projection.h).
std::vector<ceres::ResidualBlockId> UnevaluableResidualBlocks(const ceres::Problem& problem);

// "; N residual(s) cannot be evaluated there, among them A, B, C", or empty
// if all can: the first three named by `describe` from their parameter
// blocks. For the message of a solve that failed.
std::string DescribeUnevaluableResiduals(const ceres::Problem& problem,
                                         const std::function<std::string(const std::vector<double*>&)>& describe);

// Whether the cost function of `residual_block` can be evaluated with its
// Jacobians at the current values and gives finite numbers.
bool EvaluableResidualBlock(const ceres::Problem& problem, ceres::ResidualBlockId residual_block);

}  // namespace portcal
