// The ideal image of a chessboard-like corner (two straight edges, blurred)
// against one pixel of a window around it, by Ceres' autodiff: the
// reference that corner_pattern_model.h (the same model with its
// derivatives written out, which corner refinement uses) is tested against.
// Block p (7): the corner's x and y (pixels), the two edges' angles, the
// mean gray, the contrast and log of the blur's sigma (pixels).
#pragma once

#include <ceres/jet.h>

#include <cmath>

#include "colmap_ext/cost/autodiff_functor.h"

namespace portcal {

// One pixel of the window: residual = model - observed gray. The model is
// integrated over the pixel's area (4 x 4 sub-samples): with a box filter an
// edge spreads over one pixel only, which a single Gaussian cannot mimic
// without trading the edge's position against its width.
struct CornerPatternResidual : AutoDiffFunctor<CornerPatternResidual, 1, 7> {
  CornerPatternResidual(double x, double y, double gray) : x_(x), y_(y), gray_(gray) {}

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    // p = cx, cy, theta1, theta2, m, a, log_sigma
    const T c1 = cos(p[2]), s1 = sin(p[2]), c2 = cos(p[3]), s2 = sin(p[3]);
    const T scale = T(1.0 / std::sqrt(2.0)) * exp(-p[6]);
    T sum = T(0);
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        const T dx = T(x_ + (i + 0.5) / 4 - 0.5) - p[0];
        const T dy = T(y_ + (j + 0.5) / 4 - 0.5) - p[1];
        sum += erf((c1 * dx + s1 * dy) * scale) * erf((c2 * dx + s2 * dy) * scale);
      }
    }
    residual[0] = p[4] + p[5] * sum / T(16) - T(gray_);
    return true;
  }

 private:
  double x_, y_, gray_;
};

}  // namespace portcal
