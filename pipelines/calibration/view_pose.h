// The pose of one view of a planar target, seen by a camera that may sit
// behind a housing, and the pieces the rig adjustments share.
#pragma once

#include <ceres/ceres.h>

#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

// Solves a calibration problem: Schur complement, tight tolerances, silent.
// Throws NumericalError("<what> did not converge: ...").
ceres::Solver::Summary SolveCalibration(ceres::Problem* problem, int max_num_iterations,
                                        int num_threads, const std::string& what);

// Dense SVD covariance (small problems; reports rank deficiency).
ceres::Covariance::Options CalibrationCovarianceOptions(int num_threads);

// Adds the view's points: X_k = camk_from_cam1 * cam1_from_target * X
// through lens and housing (fixed), residuals in pixels.
void AddRigView(const CalibrationView& view, const HousedCamera& camera, double* cam1_from_target,
                double* camk_from_cam1, double* intrinsics, ceres::Problem* problem);

// cam_from_target of a view: homography on the undistorted rays, then a
// pose-only solve through lens and housing. Throws NumericalError.
Rigid3d EstimateViewPose(const CalibrationView& view, const HousedCamera& camera, int num_threads);

// RMS (px) of a view at a pose, through lens and housing.
double ViewRms(const CalibrationView& view, const HousedCamera& camera,
               const Rigid3d& cam_from_target);

// Held-out error of a calibration: each view's pose estimated alone (pose
// only, everything else fixed), RMS over all points of all views.
double HeldOutRms(const std::vector<CalibrationView>& views, const HousedCamera& camera,
                  int num_threads);

}  // namespace portcal
