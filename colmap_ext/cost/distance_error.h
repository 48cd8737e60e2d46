// The distance of two points against a known length (a marker's side as
// the scale of a reconstruction), in units of sigma: |a - b| - length.
// Blocks: a (3), b (3), metres.
#pragma once

#include <ceres/jet.h>

#include "colmap_ext/cost/autodiff_functor.h"

namespace portcal {

struct DistanceError : AutoDiffFunctor<DistanceError, 1, 3, 3> {
  DistanceError(double length, double sigma) : length_(length), inv_sigma_(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const T dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    residual[0] = (ceres::sqrt(dx * dx + dy * dy + dz * dz) - T(length_)) * T(inv_sigma_);
    return true;
  }
  double length_, inv_sigma_;
};

}  // namespace portcal
