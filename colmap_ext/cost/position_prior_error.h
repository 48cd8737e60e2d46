// A position prior (navigation: GNSS, USBL, DVL) on a camera centre, in
// units of sigma: the centre of cam_from_world (quaternion x,y,z,w +
// translation), -R^T t, against the prior, both metres in the world frame.
#pragma once

#include <Eigen/Geometry>

#include "colmap_ext/cost/autodiff_functor.h"

namespace portcal {

struct PositionPriorError : AutoDiffFunctor<PositionPriorError, 3, 7> {
  PositionPriorError(const Eigen::Vector3d& prior, double sigma)
      : prior(prior), inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(pose + 4);
    const Eigen::Matrix<T, 3, 1> centre = -(rotation.conjugate() * translation);
    for (int k = 0; k < 3; ++k) residual[k] = (centre[k] - T(prior[k])) * T(inv_sigma);
    return true;
  }
  Eigen::Vector3d prior;
  double inv_sigma;
};

}  // namespace portcal
