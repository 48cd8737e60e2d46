// What a held block's covariance adds to a free block's, on a problem
// linear in both (where first order is exact): dx/dtheta Sigma dx/dtheta'
// with dx/dtheta = -(A'A)^-1 A'B, in the free block's ambient coordinates
// through its manifold; and the problem left as it was.
#include "pipelines/calibration/held_block_covariance.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace portcal {
namespace {

// r = A x + B theta - b, one row each.
struct LinearRow {
  LinearRow(const Eigen::Vector3d& a, const Eigen::Vector2d& b, double target)
      : a(a), b(b), target(target) {}
  template <typename T>
  bool operator()(const T* x, const T* theta, T* residual) const {
    residual[0] =
        a[0] * x[0] + a[1] * x[1] + a[2] * x[2] + b[0] * theta[0] + b[1] * theta[1] - target;
    return true;
  }
  Eigen::Vector3d a;
  Eigen::Vector2d b;
  double target;
};

TEST(HeldBlockCovariance, EqualsTheLinearSensitivityTimesTheHeldCovariance) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(12, 3), b = Eigen::MatrixXd::Random(12, 2);
  Eigen::VectorXd target = Eigen::VectorXd::Random(12);
  double x[3] = {0, 0, 0}, theta[2] = {0.3, -0.2};
  ceres::Problem problem;
  for (int r = 0; r < 12; ++r) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LinearRow, 1, 3, 2>(new LinearRow(
                                 a.row(r).transpose(), b.row(r).transpose(), target[r])),
                             nullptr, x, theta);
  }
  problem.SetParameterBlockConstant(theta);
  // x[1] held by a manifold: its ambient row and column stay zero.
  problem.SetManifold(x, new ceres::SubsetManifold(3, {1}));
  Eigen::Matrix2d sigma;
  sigma << 0.04, 0.01, 0.01, 0.09;
  const Eigen::MatrixXd added = HeldBlockCovarianceContribution(&problem, theta, sigma, x);

  Eigen::MatrixXd free(12, 2);
  free << a.col(0), a.col(2);
  const Eigen::MatrixXd sensitivity = -(free.transpose() * free).inverse() * free.transpose() * b;
  const Eigen::Matrix2d expected = sensitivity * sigma * sensitivity.transpose();
  ASSERT_EQ(added.rows(), 3);
  EXPECT_NEAR(added(0, 0), expected(0, 0), 1e-12);
  EXPECT_NEAR(added(0, 2), expected(0, 1), 1e-12);
  EXPECT_NEAR(added(2, 2), expected(1, 1), 1e-12);
  EXPECT_EQ(added.row(1).norm(), 0);
  EXPECT_TRUE(problem.IsParameterBlockConstant(theta));
}

}  // namespace
}  // namespace portcal
