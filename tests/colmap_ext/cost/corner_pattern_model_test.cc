// The corner model with its derivatives written out (and its tabulated erf)
// against the autodiff residual it replaces in corner refinement.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>

#include "colmap_ext/cost/corner_pattern_model.h"
#include "colmap_ext/cost/corner_pattern_residual.h"

namespace portcal {
namespace {

TEST(TabulatedErf, FollowsErfAndItsSlope) {
  const TabulatedErf& table = TabulatedErf::Get();
  double max_value_error = 0, max_slope_error = 0;
  for (double u = -8; u <= 8; u += 1.0 / 1024 + 1e-7) {
    double slope = 0;
    max_value_error = std::max(max_value_error, std::abs(table(u, &slope) - std::erf(u)));
    max_slope_error = std::max(max_slope_error, std::abs(slope - 2 / std::sqrt(M_PI) * std::exp(-u * u)));
  }
  // Cubic Hermite with nodes 1/64 apart: h^4 / 384 max|erf''''| ~ 1e-9 for
  // the value, h^3 / 24 max|erf''''| ~ 1e-6 for the slope.
  EXPECT_LT(max_value_error, 2e-9);
  EXPECT_LT(max_slope_error, 1e-6);
  double slope = 1;
  EXPECT_TRUE(std::isnan(table(std::nan(""), &slope))) << "NaN passes through";
}

TEST(CornerPatternModel, ValueAndDerivativesMatchTheAutodiffResidual) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    double p[7] = {10 + u(rng), 12 + u(rng), 0.3 + 0.5 * u(rng), 1.9 + 0.5 * u(rng),
                   120 + 20 * u(rng), 60 * u(rng), std::log(0.8) + 0.6 * u(rng)};
    const double x = 10.5 + std::round(4 * u(rng)), y = 12.5 + std::round(4 * u(rng)), gray = 100;
    const std::unique_ptr<ceres::CostFunction> autodiff(CornerPatternResidual::Create(x, y, gray));
    double residual = 0, jacobian[7];
    double* parameters[] = {p};
    double* jacobians[] = {jacobian};
    ASSERT_TRUE(autodiff->Evaluate(parameters, &residual, jacobians));
    double gradient[7];
    const double value = CornerPatternModel(p).Evaluate(x, y, gradient);
    // The table's 2e-9 per erf, times the contrast.
    EXPECT_NEAR(value - gray, residual, 1e-6) << trial;
    for (int k = 0; k < 7; ++k) {
      EXPECT_NEAR(gradient[k], jacobian[k], 1e-4 * (1 + std::abs(jacobian[k]))) << "trial " << trial << ", p" << k;
    }
    EXPECT_EQ(CornerPatternModel(p).Evaluate(x, y, nullptr), value);
  }
}

// With one sample the model is the pattern at the pixel's centre; its
// derivatives agree with central differences.
TEST(CornerPatternModel, OneSampleIsThePatternAtThePixelCentre) {
  const double p[7] = {10.3, 12.1, 0.4, 2.0, 120, 50, std::log(0.7)};
  const double x = 11.5, y = 13.5;
  const double scale = 1 / (std::sqrt(2.0) * 0.7);
  const double u1 = (std::cos(p[2]) * (x - p[0]) + std::sin(p[2]) * (y - p[1])) * scale;
  const double u2 = (std::cos(p[3]) * (x - p[0]) + std::sin(p[3]) * (y - p[1])) * scale;
  double gradient[7];
  EXPECT_NEAR(CornerPatternModel(p, 1).Evaluate(x, y, gradient), 120 + 50 * std::erf(u1) * std::erf(u2), 1e-6);
  for (int k = 0; k < 7; ++k) {
    double plus[7], minus[7];
    std::copy(p, p + 7, plus);
    std::copy(p, p + 7, minus);
    plus[k] += 1e-6;
    minus[k] -= 1e-6;
    const double numeric =
        (CornerPatternModel(plus, 1).Evaluate(x, y, nullptr) - CornerPatternModel(minus, 1).Evaluate(x, y, nullptr)) / 2e-6;
    EXPECT_NEAR(gradient[k], numeric, 1e-4 * (1 + std::abs(numeric))) << "p" << k;
  }
}

}  // namespace
}  // namespace portcal
