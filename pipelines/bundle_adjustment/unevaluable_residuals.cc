#include "pipelines/bundle_adjustment/unevaluable_residuals.h"

#include <Eigen/Core>
#include <sstream>

namespace portcal {

namespace {

bool EvaluableResidualBlock(const ceres::Problem& problem, ceres::ResidualBlockId residual_block) {
  const ceres::CostFunction* cost = problem.GetCostFunctionForResidualBlock(residual_block);
  std::vector<double*> parameters;
  problem.GetParameterBlocksForResidualBlock(residual_block, &parameters);
  const int num_residuals = cost->num_residuals();
  Eigen::VectorXd residuals(num_residuals);
  std::vector<Eigen::VectorXd> jacobians;
  std::vector<double*> jacobian_ptrs;
  for (const int32_t size : cost->parameter_block_sizes())
    jacobians.emplace_back(num_residuals * size);
  for (Eigen::VectorXd& jacobian : jacobians) jacobian_ptrs.push_back(jacobian.data());
  if (!cost->Evaluate(parameters.data(), residuals.data(), jacobian_ptrs.data())) return false;
  if (!residuals.allFinite()) return false;
  for (const Eigen::VectorXd& jacobian : jacobians) {
    if (!jacobian.allFinite()) return false;
  }
  return true;
}

}  // namespace

std::vector<ceres::ResidualBlockId> UnevaluableResidualBlocks(const ceres::Problem& problem) {
  std::vector<ceres::ResidualBlockId> blocks;
  problem.GetResidualBlocks(&blocks);
  std::vector<ceres::ResidualBlockId> failing;
  for (const ceres::ResidualBlockId block : blocks) {
    if (!EvaluableResidualBlock(problem, block)) failing.push_back(block);
  }
  return failing;
}

std::string DescribeUnevaluableResiduals(
    const ceres::Problem& problem,
    const std::function<std::string(const std::vector<double*>&)>& describe) {
  const std::vector<ceres::ResidualBlockId> failing = UnevaluableResidualBlocks(problem);
  if (failing.empty()) return "";
  std::ostringstream out;
  out << "; " << failing.size() << " residual(s) cannot be evaluated there, among them";
  for (size_t i = 0; i < failing.size() && i < 3; ++i) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(failing[i], &blocks);
    out << (i ? "," : "") << " " << describe(blocks);
  }
  return out.str();
}

}  // namespace portcal
