// The blurred-step model of the pixels in a band along a marker's side,
// with its derivatives written out (marker_edge_refinement.cc fits it;
// tested against central differences).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "colmap_ext/cost/erf_pixel_average.h"

namespace portcal {

struct BandPixel {
  double t, s, gray;  // along the side (over its length), along the outward normal, gray
};

// The blurred-step model of a band's pixels and its least squares. Each
// pixel's gray is m(t) + k(t) * (the mean over the pixel of erf(u)),
// u = (s - d(t)) / (sqrt(2) sigma): s the pixel centre's offset along the
// outward normal, t its place along the side (0..1), d(t) the edge's offset
// (quadratic for a long side). The levels m and k vary linearly along the
// side: shading across a tilted face, vignetting or a light's fall-off make
// them, and with constant levels their trend would be taken up by the
// edge's slope (the gray a level trend adds at a pixel correlates with t
// times the edge's profile), turning the corners.
struct EdgeBandModel {
  static constexpr int kNumParams = 8;  // c0, c1, c2, m0, m1, k0, k1, log sigma
  using Params = Eigen::Matrix<double, kNumParams, 1>;
  using Normal = Eigen::Matrix<double, kNumParams, kNumParams>;
  Eigen::Vector2d n;
  bool quadratic = false;

  // Gauss-Newton's normal equations at `q` over the pixels `use` marks;
  // returns the cost.
  double Linearise(const std::vector<BandPixel>& band, const std::vector<char>& use,
                   const Params& q, Normal* jtj, Params* jtr) const {
    const double w = std::exp(-q[7]) / std::sqrt(2.0);
    const double width_x = w * n.x(), width_y = w * n.y();
    jtj->setZero();
    jtr->setZero();
    double cost = 0;
    for (size_t i = 0; i < band.size(); ++i) {
      if (!use[i]) continue;
      const BandPixel& p = band[i];
      const double tc = p.t - 0.5;
      double u0 = 0;
      ErfPixelAverage m;
      const double r = Residual(p, q, &u0, &m);
      const double k = q[5] + q[6] * tc;
      const double d_d = -k * m.d_u0 * w;  // d value / d d
      Params g;
      g << d_d, d_d * p.t, quadratic ? d_d * p.t * p.t : 0.0, 1.0, tc, m.value, m.value * tc,
          -k * (m.d_u0 * u0 + m.d_a * width_x + m.d_b * width_y);
      jtj->noalias() += g * g.transpose();  // fixed 8 x 8: faster than a rank update here
      *jtr += r * g;
      cost += 0.5 * r * r;
    }
    if (!quadratic) (*jtj)(2, 2) = 1;  // c2 stays 0
    return cost;
  }

  // Model minus gray at `p`; `u0` and the pixel average `m` for the
  // derivatives.
  double Residual(const BandPixel& p, const Params& q, double* u0, ErfPixelAverage* m) const {
    const double w = std::exp(-q[7]) / std::sqrt(2.0);
    const double tc = p.t - 0.5;
    *u0 = (p.s - (q[0] + p.t * (q[1] + p.t * q[2]))) * w;
    *m = AverageErfOverPixel(*u0, w * n.x(), w * n.y());
    return q[3] + q[4] * tc + (q[5] + q[6] * tc) * m->value - p.gray;
  }
};

}  // namespace portcal
