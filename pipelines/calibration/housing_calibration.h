// Housing calibration from views of a planar target through a flat or dome
// port, with the camera's in-air intrinsics known (and by default fixed).
//
// Initialisation from the data: every ray of an axial camera (both ports
// are) meets the refraction axis, so the ray direction d of a pixel, the
// axis a and the target point X are coplanar: d^T [a]x [r1 r2 t] (x, y, 1)^T
// = 0, a "fundamental matrix" F = [a]x H between the target plane and the
// rays whose left null vector is the axis (She et al., "Refractive geometry
// for underwater domes", ISPRS J. 2022). One F per view, the axis as the
// common null vector of all of them; then the magnitude (flat: interface
// distance, dome: decentering along the axis) by a coarse 1-D search scored
// by pose-only residuals. Then Ceres over the poses and the housing (flat:
// normal on the unit sphere + distance; dome: centre), first with the
// virtual-camera error, then with the exact reprojection error, which gives
// the reported RMS and, through the covariance scaled by the residual
// variance, the standard deviations.
//
// With the camera's in-air views (InAirViews), the exact solve is joint:
// the intrinsics are shared by both sets and refined by both, each set
// weighted by its own residual variance, so the housing's standard
// deviations include what the in-air calibration does not know. Without
// them the intrinsics are taken as exact (or refined from the underwater
// views alone), and the housing's standard deviations are smaller than its
// errors whenever the intrinsics are not.
#pragma once

#include <optional>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

struct HousingCalibrationSettings {
  bool refine_intrinsics = false;    // jointly with the housing
  bool initialize_from_data = true;  // else start from the given parameters
  // mrcal's board sag (board_warp.h): the underwater views' own, and the
  // in-air views' own unless InAirViews::share_board_warp.
  bool estimate_board_warp = false;
  int max_num_iterations = 200;
  int num_threads = 2;
  void Check() const;  // throws OptionError
};

// The camera's views in air (same lens, focus and zoom), solved jointly.
struct InAirViews {
  std::vector<CalibrationView> views;
  // One sag for both sets: only for the same board in one session. A board's
  // sag is a property of the session, not of the board: on the real dome
  // set it differs by 10 sigma between air and water (docs/calibration.md).
  bool share_board_warp = false;
  std::vector<int> fixed_params;  // intrinsics held, as in the in-air calibration
};

struct HousingCalibrationResult {
  Housing housing;
  // Per parameter; 0 for constants and fixed values, -1 where the
  // covariance is rank deficient (undetermined).
  std::vector<double> housing_std_dev;
  Camera camera;
  std::vector<double> camera_std_dev;
  // The full covariances (the residual variance applied) of the housing's
  // and, when refined, the camera's parameters; zero rows and columns for
  // what is held, empty when undetermined. With a lens covariance given
  // and the intrinsics held, the housing's includes what the lens's adds.
  Eigen::MatrixXd housing_covariance, camera_covariance;
  bool lens_covariance_propagated = false;
  Eigen::Vector3d initial_axis = Eigen::Vector3d::Zero();  // from the F matrices
  double overall_rms_px = 0;
  double residual_sigma_px = 0;
  int num_points = 0;
  std::vector<CalibratedView> views;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();  // metres, when estimated
  Eigen::Vector2d board_warp_std_dev = Eigen::Vector2d::Zero();
  bool board_warp_estimated = false;
  // The in-air views' own sag (joint solve, warp not shared).
  std::optional<Eigen::Vector2d> in_air_board_warp, in_air_board_warp_std_dev;
  // The joint solve's in-air half (empty without InAirViews).
  std::vector<CalibratedView> in_air_views;
  double in_air_rms_px = 0;
  double in_air_residual_sigma_px = 0;
};

// `housing` gives the model, the constants (thickness, radius, indices) and
// the starting guess; `camera` the intrinsics (the start when refined).
// `lens_covariance` (camera.params square, optional): the given
// intrinsics' own covariance; when they are held, it is propagated into the
// housing's (first order, held_block_covariance.h). Throws NumericalError
// when the solve fails.
HousingCalibrationResult CalibrateHousing(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const Housing& housing,
                                          const HousingCalibrationSettings& settings,
                                          const InAirViews* in_air = nullptr,
                                          const Eigen::MatrixXd* lens_covariance = nullptr);

}  // namespace portcal
