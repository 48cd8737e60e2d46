// What a held parameter block's own uncertainty adds to the estimate of a
// free one, to first order: a housing calibrated on given intrinsics
// inherits their error. At the optimum of r(x, theta) (x free, theta held)
// the estimate moves with theta as dx/dtheta = -(Jx' Jx)^-1 Jx' Jtheta
// (Gauss-Newton, the implicit function theorem), so theta's covariance adds
// dx/dtheta Sigma_theta dx/dtheta' to x's. Exact for a problem linear in
// both; a linearisation otherwise (the held values' errors are small
// against the scale on which the Jacobians change).
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>

namespace portcal {

// The covariance `held_covariance` (ambient, held->size() square: the
// held block's parameters' own, e.g. from its calibration file) adds to
// block `of`, in `of`'s ambient coordinates (through its manifold's Plus
// Jacobian). `problem` is at its solution with `held` constant and `of`
// free; it is left as it was. Throws NumericalError when the free blocks'
// information is singular.
Eigen::MatrixXd HeldBlockCovarianceContribution(ceres::Problem* problem, double* held,
                                                const Eigen::MatrixXd& held_covariance, double* of);

}  // namespace portcal
