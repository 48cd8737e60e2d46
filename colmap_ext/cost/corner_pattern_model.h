// The ideal corner pattern of CornerPatternResidual with its derivatives
// written out, for the fixed-size Levenberg-Marquardt of corner refinement
// (a Ceres problem per corner spent most of target extraction's time in
// Jet arithmetic and problem set-up). Tested against the autodiff residual.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "colmap_ext/cost/erf_pixel_average.h"
#include "colmap_ext/cost/tabulated_erf.h"

namespace portcal {

// Where to sample a pixel to average over it: n nodes per axis on
// [-1/2, 1/2] about its centre, with weights summing to 1.
struct PixelRule {
  static constexpr int kMaxNodes = 8;
  int n = 1;
  std::array<double, kMaxNodes> nodes{}, weights{};

  // n equally spaced sub-samples (1: the centre).
  static PixelRule Midpoint(int n) {
    PixelRule rule;
    rule.n = std::clamp(n, 1, kMaxNodes);
    for (int i = 0; i < rule.n; ++i) {
      rule.nodes[i] = (i + 0.5) / rule.n - 0.5;
      rule.weights[i] = 1.0 / rule.n;
    }
    return rule;
  }

  // Gauss-Legendre with 3 or 5 nodes: exact for polynomials of degree 5 or
  // 9 over the pixel, far better than as many equal sub-samples where the
  // edges are smooth at the pixel's scale.
  static PixelRule GaussLegendre(int n) {
    PixelRule rule;
    if (n <= 3) {
      rule.n = 3;
      rule.nodes = {-0.3872983346207417, 0, 0.3872983346207417};
      rule.weights = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    } else {
      rule.n = 5;
      rule.nodes = {-0.4530899229693320, -0.2692346550528415, 0, 0.2692346550528415,
                    0.4530899229693320};
      rule.weights = {0.1184634425280945, 0.2393143352496832, 0.2844444444444444,
                      0.2393143352496832, 0.1184634425280945};
    }
    return rule;
  }
};

// Parameters p (7): the corner's x and y (pixels), the two edges' normal
// angles, the mean gray, the contrast and log of the blur's sigma (pixels).
class CornerPatternModel {
 public:
  static constexpr int kNumParams = 7;

  // `samples_per_axis`: 4 integrates over the pixel's area (4 x 4
  // sub-samples), as CornerPatternResidual; 1 samples the pixel's centre
  // only (16 times cheaper; the blur then absorbs the pixel's box), for the
  // first iterations of a fit.
  explicit CornerPatternModel(const double* p, int samples_per_axis = 4)
      : CornerPatternModel(p, PixelRule::Midpoint(samples_per_axis)) {}

  CornerPatternModel(const double* p, const PixelRule& rule)
      : rule_(rule),
        cx_(p[0]),
        cy_(p[1]),
        c1_(std::cos(p[2])),
        s1_(std::sin(p[2])),
        c2_(std::cos(p[3])),
        s2_(std::sin(p[3])),
        mean_(p[4]),
        contrast_(p[5]),
        scale_(std::exp(-p[6]) / std::sqrt(2.0)) {}

  // How many of erf's units a pixel spans across the wider-spread edge.
  double PixelSpan() const {
    return scale_ * std::max(std::abs(c1_) + std::abs(s1_), std::abs(c2_) + std::abs(s2_));
  }

  // Which edges vary over the pixel whose centre is (x, y): an edge is flat
  // there when the whole pixel lies beyond the erf table's range plus
  // `margin` (erf's units) from it.
  // Bit 0: the first edge varies, bit 1: the second.
  enum Region : int { kFlat = 0, kEdge1 = 1, kEdge2 = 2, kCorner = 3 };
  Region Classify(double x, double y, double margin) const {
    const bool flat1 = std::abs(U1(x, y)) > TabulatedErf::kRange + margin + Reach1(0.5);
    const bool flat2 = std::abs(U2(x, y)) > TabulatedErf::kRange + margin + Reach2(0.5);
    return flat1 ? (flat2 ? kFlat : kEdge2) : (flat2 ? kEdge1 : kCorner);
  }

  // The model's gray at the pixel whose centre is (x, y), integrated over
  // the pixel's area: in closed form where one edge varies over the pixel
  // (the other's erf is then its sign; erf_pixel_average.h), by
  // the rule's sub-samples where both do. `region` comes from
  // Classify, kept for a whole fit so that the model stays smooth. With
  // `gradient`, the derivatives with respect to p.
  double EvaluateArea(double x, double y, Region region, double* gradient) const {
    if (region == kCorner) return Evaluate(x, y, gradient);
    const double u1 = U1(x, y), u2 = U2(x, y);
    const double sign1 = u1 > 0 ? 1.0 : -1.0, sign2 = u2 > 0 ? 1.0 : -1.0;
    if (region == kFlat) {
      if (gradient != nullptr) {
        for (int k = 0; k < kNumParams; ++k) gradient[k] = 0;
        gradient[4] = 1;
        gradient[5] = sign1 * sign2;
      }
      return mean_ + contrast_ * sign1 * sign2;
    }
    const bool first = region == kEdge1;
    const double c = first ? c1_ : c2_, s = first ? s1_ : s2_, u = first ? u1 : u2;
    const double other_sign = first ? sign2 : sign1;
    const double a = scale_ * c, b = scale_ * s;
    const ErfPixelAverage m = AverageErfOverPixel(u, a, b);
    if (gradient != nullptr) {
      const double k = contrast_ * other_sign;
      const double dx = x - cx_, dy = y - cy_;
      gradient[0] = -k * m.d_u0 * a;
      gradient[1] = -k * m.d_u0 * b;
      // The edge's angle turns u0 and the pixel's widths a, b.
      const double d_angle = k * (m.d_u0 * scale_ * (c * dy - s * dx) - m.d_a * b + m.d_b * a);
      gradient[2] = first ? d_angle : 0;
      gradient[3] = first ? 0 : d_angle;
      gradient[4] = 1;
      gradient[5] = other_sign * m.value;
      // u0, a and b all scale with 1 / sigma.
      gradient[6] = -k * (m.d_u0 * u + m.d_a * a + m.d_b * b);
    }
    return mean_ + contrast_ * other_sign * m.value;
  }

  // The model's gray at the pixel whose centre is (x, y), averaged over the
  // rule's sub-samples of the pixel; with `gradient`, its derivatives with
  // respect to p.
  double Evaluate(double x, double y, double* gradient) const {
    const TabulatedErf& erf = TabulatedErf::Get();
    // Where a line is farther from the whole pixel than the table's range,
    // its erf is the same ±1 at every sub-sample and its slope 0: the
    // sub-samples need the other line only (or nothing), with the same
    // numbers as when computed.
    const double centre_u1 = U1(x, y), centre_u2 = U2(x, y);
    const double half_extent = rule_.nodes[rule_.n - 1];  // of the sub-samples about the centre
    const bool flat1 = std::abs(centre_u1) > TabulatedErf::kRange + Reach1(half_extent);
    const bool flat2 = std::abs(centre_u2) > TabulatedErf::kRange + Reach2(half_extent);
    double sum = 0, d_cx = 0, d_cy = 0, d_t1 = 0, d_t2 = 0, d_log_sigma = 0;
    if (flat1 && flat2) {
      sum = (centre_u1 > 0 ? 1.0 : -1.0) * (centre_u2 > 0 ? 1.0 : -1.0);
    } else {
      for (int i = 0; i < rule_.n; ++i) {
        const double dx = x + rule_.nodes[i] - cx_;
        for (int j = 0; j < rule_.n; ++j) {
          const double dy = y + rule_.nodes[j] - cy_;
          const double w = rule_.weights[i] * rule_.weights[j];
          const double u1 = (c1_ * dx + s1_ * dy) * scale_;
          const double u2 = (c2_ * dx + s2_ * dy) * scale_;
          double slope1 = 0, slope2 = 0;
          const double e1 = flat1 ? (u1 > 0 ? 1.0 : -1.0) : erf(u1, &slope1);
          const double e2 = flat2 ? (u2 > 0 ? 1.0 : -1.0) : erf(u2, &slope2);
          sum += w * e1 * e2;
          if (gradient == nullptr) continue;
          // d(e1 e2) = erf'(u1) e2 du1 + e1 erf'(u2) du2
          const double a = w * slope1 * e2;
          const double b = w * slope2 * e1;
          d_cx -= (a * c1_ + b * c2_) * scale_;
          d_cy -= (a * s1_ + b * s2_) * scale_;
          d_t1 += a * (c1_ * dy - s1_ * dx) * scale_;
          d_t2 += b * (c2_ * dy - s2_ * dx) * scale_;
          d_log_sigma -= a * u1 + b * u2;
        }
      }
    }
    if (gradient != nullptr) {
      gradient[0] = contrast_ * d_cx;
      gradient[1] = contrast_ * d_cy;
      gradient[2] = contrast_ * d_t1;
      gradient[3] = contrast_ * d_t2;
      gradient[4] = 1;
      gradient[5] = sum;
      gradient[6] = contrast_ * d_log_sigma;
    }
    return mean_ + contrast_ * sum;
  }

 private:
  double U1(double x, double y) const { return (c1_ * (x - cx_) + s1_ * (y - cy_)) * scale_; }
  double U2(double x, double y) const { return (c2_ * (x - cx_) + s2_ * (y - cy_)) * scale_; }
  // How far u changes from a pixel's centre to points `half_extent` away in
  // x and y.
  double Reach1(double half_extent) const {
    return half_extent * (std::abs(c1_) + std::abs(s1_)) * scale_;
  }
  double Reach2(double half_extent) const {
    return half_extent * (std::abs(c2_) + std::abs(s2_)) * scale_;
  }

  PixelRule rule_;
  double cx_, cy_, c1_, s1_, c2_, s2_, mean_, contrast_, scale_;
};

}  // namespace portcal
