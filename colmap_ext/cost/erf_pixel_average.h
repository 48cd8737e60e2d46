// The mean of erf(u0 + a x + b y) over a pixel, x and y in [-1/2, 1/2]: a
// blurred straight edge integrated over the pixel's area in closed form.
//
// With F1(u) = u erf(u) + exp(-u^2) / sqrt(pi) and
// F2(u) = (u^2 / 2 + 1/4) erf(u) + u exp(-u^2) / (2 sqrt(pi)), the
// antiderivatives of erf and F1, the mean is the second difference
//   [F2(u0 + A + B) - F2(u0 + A - B) - F2(u0 - A + B) + F2(u0 - A - B)] / (a b)
// with A = a / 2, B = b / 2: exact where sub-sampling the pixel (as the
// autodiff reference does, 4 x 4) is a staircase for sharp edges, and a
// handful of erf evaluations instead of 16. The difference loses digits as
// a or b goes to 0 (an edge along a pixel row or column), so a narrow
// direction is integrated by 3-point Gauss-Legendre instead, exact to
// ~w^6 / 2e6 for a width w < 1/4.
#pragma once

#include <cmath>
#include <utility>

#include "colmap_ext/cost/tabulated_erf.h"

namespace portcal {

struct ErfPixelAverage {
  double value = 0;
  double d_u0 = 0, d_a = 0, d_b = 0;  // derivatives of value
};

namespace erf_pixel_average_internal {

// Gauss-Legendre nodes on [-1/2, 1/2] and their weights (summing to 1).
constexpr double kNodes[3] = {-0.3872983346207417, 0.0, 0.3872983346207417};
constexpr double kWeights[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};

// erf, F1 and F2 at u.
struct Antiderivatives {
  double erf, f1, f2;
};
inline Antiderivatives At(double u) {
  double slope = 0;
  const double e = TabulatedErf::Get()(u, &slope);
  // exp(-u^2) / sqrt(pi) is half of erf's slope.
  return {e, u * e + 0.5 * slope, (0.5 * u * u + 0.25) * e + 0.25 * u * slope};
}

// Exact in x (|a| not small), Gauss-Legendre in y.
inline ErfPixelAverage ExactInX(double u0, double a, double b) {
  ErfPixelAverage m;
  const double half = 0.5 * a;
  for (int k = 0; k < 3; ++k) {
    const double u = u0 + b * kNodes[k];
    const Antiderivatives hi = At(u + half), lo = At(u - half);
    const double mean_x = (hi.f1 - lo.f1) / a;  // mean over x at this y
    const double slope_x = (hi.erf - lo.erf) / a;
    m.value += kWeights[k] * mean_x;
    m.d_u0 += kWeights[k] * slope_x;
    m.d_a += kWeights[k] * (0.5 * (hi.erf + lo.erf) - mean_x) / a;
    m.d_b += kWeights[k] * kNodes[k] * slope_x;
  }
  return m;
}

// Gauss-Legendre in both (a and b small: the edge is wide).
inline ErfPixelAverage Sampled(double u0, double a, double b) {
  ErfPixelAverage m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double slope = 0;
      const double w = kWeights[i] * kWeights[j];
      m.value += w * TabulatedErf::Get()(u0 + a * kNodes[i] + b * kNodes[j], &slope);
      m.d_u0 += w * slope;
      m.d_a += w * kNodes[i] * slope;
      m.d_b += w * kNodes[j] * slope;
    }
  }
  return m;
}

// The closed-form second difference (|a| and |b| not small).
inline ErfPixelAverage Exact(double u0, double a, double b) {
  const double ha = 0.5 * a, hb = 0.5 * b;
  const Antiderivatives pp = At(u0 + ha + hb), pm = At(u0 + ha - hb), mp = At(u0 - ha + hb),
                        mm = At(u0 - ha - hb);
  const double ab = a * b;
  ErfPixelAverage m;
  m.value = (pp.f2 - pm.f2 - mp.f2 + mm.f2) / ab;
  m.d_u0 = (pp.f1 - pm.f1 - mp.f1 + mm.f1) / ab;
  m.d_a = (pp.f1 - pm.f1 + mp.f1 - mm.f1) / (2 * ab) - m.value / a;
  m.d_b = (pp.f1 + pm.f1 - mp.f1 - mm.f1) / (2 * ab) - m.value / b;
  return m;
}

}  // namespace erf_pixel_average_internal

inline ErfPixelAverage AverageErfOverPixel(double u0, double a, double b) {
  namespace internal = erf_pixel_average_internal;
  // Below this width (in erf's units) a direction is integrated by
  // Gauss-Legendre: the second difference would divide the table's ~1e-6
  // error in F2 by a b.
  constexpr double kNarrow = 0.25;
  const bool swap = std::abs(a) < std::abs(b);
  if (swap) std::swap(a, b);
  ErfPixelAverage m = std::abs(a) < kNarrow   ? internal::Sampled(u0, a, b)
                      : std::abs(b) < kNarrow ? internal::ExactInX(u0, a, b)
                                              : internal::Exact(u0, a, b);
  if (swap) std::swap(m.d_a, m.d_b);
  return m;
}

}  // namespace portcal
