// What a calibration estimates, as the parameter blocks whose information
// a view of the target adds: a camera calibration's intrinsics (less those
// held) and, when fitted, the board's warp; or a housing calibration's port
// (the model's refined parameters, the in-air intrinsics given). Next-pose
// guidance and the projection uncertainty measure views by it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/guidance/calibration_information.h"

namespace portcal {

// mrcal's two-parameter board sag (colmap_ext/cost/board_warp.h) as an
// unknown: its value and the board's extent (x min, x max, y min, y max)
// that scales (u, v).
struct BoardWarpUnknown {
  Eigen::Vector2d value = Eigen::Vector2d::Zero();
  Eigen::Vector4d extent = Eigen::Vector4d(0, 1, 0, 1);
};

struct CalibrationUnknowns {
  // The current estimate: the camera, and for a housing calibration the
  // housing (its model gives what is refined).
  HousedCamera camera;
  bool housing_calibration = false;
  std::vector<int> fixed_intrinsics;  // camera calibration: indices held
  // Camera calibration in air: the board's warp, estimated with the
  // intrinsics (its two unknowns come after theirs). Behind a housing the
  // board is held flat here.
  std::optional<BoardWarpUnknown> board_warp;

  // Throws InputError: a housing calibration without a housing, or a board
  // warp behind a housing.
  void Check() const;
  // Tangent size of the unknowns (a flat port's normal counts 2).
  int NumUnknowns() const;
};

// Gauss-Newton information (J'J, pixel residuals of unit variance) that a
// view of `points_in_target` at `cam_from_target` adds on the unknowns, its
// own pose marginalised out, with what the mean-frames uncertainty needs
// of the pose (calibration_information.h). Points that do not project
// (behind the camera, total internal reflection) add none.
CalibrationInformation ViewInformation(const CalibrationUnknowns& unknowns,
                                       const std::vector<Eigen::Vector3d>& points_in_target,
                                       const Rigid3d& cam_from_target);

// At points fixed in the camera frame: d pixel / d unknowns (2 x
// NumUnknowns, tangent; zero for the board warp) and d pixel / d point
// (2 x 3); a row pair of zeros in both where a point does not project.
struct ProjectionJacobians {
  Eigen::MatrixXd unknowns;  // 2 n x NumUnknowns
  Eigen::MatrixXd point;     // 2 n x 3
};
ProjectionJacobians ProjectionJacobian(const CalibrationUnknowns& unknowns,
                                       const std::vector<Eigen::Vector3d>& points_in_cam);

}  // namespace portcal
