// Helpers that let one templated body serve double and ceres::Jet.
#pragma once

#include <ceres/jet.h>

namespace portcal {

// The value part of a scalar: the double itself, or a Jet's `a`.
inline double ScalarPart(double x) { return x; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& x) {
  return ScalarPart(x.a);
}

template <typename T>
bool IsFinite(const T& x) {
  return std::isfinite(ScalarPart(x));
}

}  // namespace portcal
