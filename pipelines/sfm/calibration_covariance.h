// Covariance of a bundle adjustment's calibration parameters with the 3-D
// points marginalised out: the Schur complement of the Gauss-Newton
// information matrix J'J on the non-point blocks (Triggs et al., "Bundle
// adjustment -- a modern synthesis", 2000, sec. 6), inverted densely. Each
// point's 3x3 block is pseudo-inverted, so a point whose depth the views do
// not fix (nearly parallel rays) adds no information instead of making the
// whole covariance rank deficient, as it does for Ceres' Covariance on the
// full problem.
#pragma once

#include <ceres/ceres.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace portcal {

// `points`: 3-parameter blocks to marginalise (each residual may touch at
// most one of them); `others`: the remaining variable blocks (poses,
// intrinsics, housings, points shared by several-point residuals). Returns
// for each of `wanted` (a subset of `others`) the standard deviation of
// every ambient parameter (0 where held by its manifold), scaled by
// `scale`. Residuals are taken without the loss function. Throws
// NumericalError when the reduced system is rank deficient, naming the
// parameter that dominates the unobservable direction by `describe(block,
// tangent index)`.
std::map<const double*, std::vector<double>> MarginalStdDevs(
    ceres::Problem* problem, const std::vector<double*>& points, const std::vector<double*>& others,
    const std::vector<const double*>& wanted, double scale,
    const std::function<std::string(const double*, int)>& describe);

}  // namespace portcal
