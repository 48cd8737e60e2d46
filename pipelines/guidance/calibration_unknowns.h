// What a calibration estimates, as the parameter blocks whose information
// a view of the target adds: a camera calibration's intrinsics (less those
// held), or a housing calibration's port (the model's refined parameters,
// the in-air intrinsics given). Next-pose guidance measures views by it.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct CalibrationUnknowns {
  // The current estimate: the camera, and for a housing calibration the
  // housing (its model gives what is refined).
  HousedCamera camera;
  bool housing_calibration = false;
  std::vector<int> fixed_intrinsics;  // camera calibration: indices held

  // Throws InputError: a housing calibration without a housing.
  void Check() const;
  // Tangent size of the unknowns (a flat port's normal counts 2).
  int NumUnknowns() const;
};

// Gauss-Newton information (J'J, pixel residuals of unit variance) that a
// view of `points_in_target` at `cam_from_target` adds on the unknowns, its
// own pose marginalised out (Schur complement: A - C B^-1 C'). Points that
// do not project (behind the camera, total internal reflection) add none.
Eigen::MatrixXd ViewInformation(const CalibrationUnknowns& unknowns,
                                const std::vector<Eigen::Vector3d>& points_in_target,
                                const Rigid3d& cam_from_target);

// d pixel / d unknowns (2 x NumUnknowns, tangent) of points fixed in the
// camera frame; a row pair of zeros where a point does not project.
Eigen::MatrixXd ProjectionJacobian(const CalibrationUnknowns& unknowns,
                                   const std::vector<Eigen::Vector3d>& points_in_cam);

}  // namespace portcal
