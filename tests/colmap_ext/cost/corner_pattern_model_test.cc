// The corner model with its derivatives written out (and its tabulated erf)
// against the autodiff residual it replaces in corner refinement.
#include "colmap_ext/cost/corner_pattern_model.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <random>

#include "colmap_ext/cost/corner_pattern_residual.h"
#include "colmap_ext/cost/erf_pixel_average.h"

namespace portcal {
namespace {

// Central differences (step 1e-6) of f in each of the corner model's 7
// parameters at p.
std::array<double, 7> CentralDifferences(const double* p,
                                         const std::function<double(const double*)>& f) {
  std::array<double, 7> derivatives;
  for (int k = 0; k < 7; ++k) {
    double plus[7], minus[7];
    std::copy(p, p + 7, plus);
    std::copy(p, p + 7, minus);
    plus[k] += 1e-6;
    minus[k] -= 1e-6;
    derivatives[k] = (f(plus) - f(minus)) / 2e-6;
  }
  return derivatives;
}

TEST(TabulatedErf, FollowsErfAndItsSlope) {
  const TabulatedErf& table = TabulatedErf::Get();
  double max_value_error = 0, max_slope_error = 0;
  for (double u = -8; u <= 8; u += 1.0 / 1024 + 1e-7) {
    double slope = 0;
    max_value_error = std::max(max_value_error, std::abs(table(u, &slope) - std::erf(u)));
    max_slope_error =
        std::max(max_slope_error, std::abs(slope - 2 / std::sqrt(M_PI) * std::exp(-u * u)));
  }
  // Cubic Hermite with nodes 1/64 apart: h^4 / 384 max|erf''''| ~ 1e-9 for
  // the value and (interpolated from its own derivatives) the slope.
  EXPECT_LT(max_value_error, 2e-9);
  EXPECT_LT(max_slope_error, 1e-8);
  double slope = 1;
  EXPECT_TRUE(std::isnan(table(std::nan(""), &slope))) << "NaN passes through";
}

TEST(CornerPatternModel, ValueAndDerivativesMatchTheAutodiffResidual) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    double p[7] = {10 + u(rng),       12 + u(rng), 0.3 + 0.5 * u(rng),          1.9 + 0.5 * u(rng),
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
      EXPECT_NEAR(gradient[k], jacobian[k], 1e-4 * (1 + std::abs(jacobian[k])))
          << "trial " << trial << ", p" << k;
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
  EXPECT_NEAR(CornerPatternModel(p, 1).Evaluate(x, y, gradient),
              120 + 50 * std::erf(u1) * std::erf(u2), 1e-6);
  const auto numeric = CentralDifferences(
      p, [&](const double* q) { return CornerPatternModel(q, 1).Evaluate(x, y, nullptr); });
  for (int k = 0; k < 7; ++k) {
    EXPECT_NEAR(gradient[k], numeric[k], 1e-4 * (1 + std::abs(numeric[k]))) << "p" << k;
  }
}

// The mean of erf over a pixel (a straight edge integrated over the pixel's
// area) against 512 x 512 sub-samples, for edges along a pixel row, across
// it diagonally, sharp and wide; its derivatives against central
// differences of itself.
TEST(ErfPixelAverage, MatchesAFinelySampledPixelWithItsDerivatives) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  const auto reference = [](double u0, double a, double b) {
    constexpr int kSamples = 512;
    double sum = 0;
    for (int i = 0; i < kSamples; ++i) {
      for (int j = 0; j < kSamples; ++j) {
        sum += std::erf(u0 + a * ((i + 0.5) / kSamples - 0.5) + b * ((j + 0.5) / kSamples - 0.5));
      }
    }
    return sum / (kSamples * kSamples);
  };
  for (int trial = 0; trial < 60; ++trial) {
    const double scale = std::exp(3 * unit(rng));  // blur sigma from ~0.04 to ~14 px
    const double angle = trial % 4 == 0 ? 1e-9 * unit(rng) : M_PI * unit(rng);  // some along a row
    const double a = scale * std::cos(angle), b = scale * std::sin(angle);
    const double u0 = 3 * unit(rng);
    const ErfPixelAverage m = AverageErfOverPixel(u0, a, b);
    // 512^2 midpoint samples: error ~ (a^2 + b^2) / (24 * 512^2) * max|erf''|.
    EXPECT_NEAR(m.value, reference(u0, a, b), 1e-5 + 2e-6 * scale * scale) << "trial " << trial;
    constexpr double h = 1e-5;
    const double d_u0 =
        (AverageErfOverPixel(u0 + h, a, b).value - AverageErfOverPixel(u0 - h, a, b).value) /
        (2 * h);
    const double d_a =
        (AverageErfOverPixel(u0, a + h, b).value - AverageErfOverPixel(u0, a - h, b).value) /
        (2 * h);
    const double d_b =
        (AverageErfOverPixel(u0, a, b + h).value - AverageErfOverPixel(u0, a, b - h).value) /
        (2 * h);
    EXPECT_NEAR(m.d_u0, d_u0, 1e-4) << "trial " << trial;
    EXPECT_NEAR(m.d_a, d_a, 1e-4) << "trial " << trial;
    EXPECT_NEAR(m.d_b, d_b, 1e-4) << "trial " << trial;
  }
}

// The pixel-area model (closed form along one edge, a product rule where
// both edges vary) against 64 x 64 centre samples of the pattern, for a
// sharp and a blurred corner, over the window's pixels; its derivatives
// against central differences with the pixels' regions held.
TEST(CornerPatternModel, PixelAreasMatchAFinelySampledPatternWithTheirDerivatives) {
  for (const double sigma : {0.15, 0.5, 1.2}) {
    const double p[7] = {20.37, 19.81, 0.35, 1.95, 120, 60, std::log(sigma)};
    const CornerPatternModel model(p, PixelRule::GaussLegendre(5));
    const CornerPatternModel fine(p, PixelRule::Midpoint(8));
    const CornerPatternModel centre(p, 1);
    int corner_pixels = 0;
    for (int row = 12; row <= 28; ++row) {
      for (int col = 12; col <= 28; ++col) {
        const double x = col + 0.5, y = row + 0.5;
        const auto region = model.Classify(x, y, 0);
        corner_pixels += region == CornerPatternModel::kCorner;
        double reference = 0;
        constexpr int kSamples = 128;
        for (int i = 0; i < kSamples; ++i) {
          for (int j = 0; j < kSamples; ++j) {
            reference += centre.Evaluate(x + (i + 0.5) / kSamples - 0.5,
                                         y + (j + 0.5) / kSamples - 0.5, nullptr);
          }
        }
        reference /= kSamples * kSamples;
        // Exact along one edge; where both vary, Gauss-Legendre (smooth
        // edges) or 8 x 8 sub-samples (sharp ones), as corner refinement
        // chooses.
        const CornerPatternModel& used = sigma < 0.3 ? fine : model;
        double gradient[7];
        const double value = used.EvaluateArea(x, y, region, gradient);
        // Where both edges cross a sharp corner's pixel 8 x 8 sub-samples
        // are still a staircase (up to ~1 gray level of 60 here); a few
        // pixels of a window only.
        const double tolerance =
            region == CornerPatternModel::kCorner ? (sigma < 0.3 ? 1.0 : 0.05) : 5e-3;
        EXPECT_NEAR(value, reference, tolerance)
            << "sigma " << sigma << " pixel " << col << "," << row;
        const PixelRule rule = sigma < 0.3 ? PixelRule::Midpoint(8) : PixelRule::GaussLegendre(5);
        const auto numeric = CentralDifferences(p, [&](const double* q) {
          return CornerPatternModel(q, rule).EvaluateArea(x, y, region, nullptr);
        });
        for (int k = 0; k < 7; ++k) {
          EXPECT_NEAR(gradient[k], numeric[k], 1e-3 * (1 + std::abs(numeric[k])))
              << "sigma " << sigma << " p" << k << " region " << region << " pixel " << col << ","
              << row;
        }
      }
    }
    EXPECT_GT(corner_pixels, 0) << sigma;
  }
}

}  // namespace
}  // namespace portcal
