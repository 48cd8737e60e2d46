// The residual blocks of a problem that cannot be evaluated, with their
// Jacobians, at the parameters' current values. Ceres reports such a block
// at a solve's start only as "Residual and Jacobian evaluation failed",
// without saying which; a failed bundle adjustment names them
// (bundle_problem.cc).
#pragma once

#include <ceres/ceres.h>

#include <functional>
#include <string>
#include <vector>

namespace portcal {

// Evaluates each residual block's cost function directly, with the
// Jacobians of all its parameter blocks (constant or not, in the ambient
// space), as the solver's first evaluation does: through the autodiff
// path, which with exact refraction can fail where the value alone does
// not (port_projection.h). A block fails if the evaluation does or gives a
// number that is not finite.
std::vector<ceres::ResidualBlockId> UnevaluableResidualBlocks(const ceres::Problem& problem);

// "; N residual(s) cannot be evaluated there, among them A, B, C", or empty
// if all can: the first three named by `describe` from their parameter
// blocks. For the message of a solve that failed.
std::string DescribeUnevaluableResiduals(
    const ceres::Problem& problem,
    const std::function<std::string(const std::vector<double*>&)>& describe);

}  // namespace portcal
