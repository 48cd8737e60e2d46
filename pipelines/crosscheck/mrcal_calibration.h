// A second, independent lens calibration of the same chessboard corners by
// mrcal's C library (mrcal_optimize), for portcal's cross_check.
//
// Why the C library and not mrcal-calibrate-cameras: the corners are
// portcal's own (stored by target_extractor), so both solvers see the same
// observations; the C call needs no Python at run time, no corners file or
// image globs, is seeded directly, and hands back what the comparison needs
// (per-corner outlier flags, the board warp and the Jacobian for the
// covariance) without parsing a tool's printout. What makes mrcal an
// independent opinion is kept: its own cost function, its board-warp model,
// its outlier rejection and its regularisation, as the tool runs them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/io/mrcal_model.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

struct MrcalCalibrationOptions {
  bool estimate_board_warp = true;  // mrcal-calibrate-cameras' default
  bool reject_outliers = true;      // ditto
  bool regularization = true;       // ditto
  bool verbose = false;             // mrcal's solver log on stderr
  void Check() const {}
};

// The chessboard as mrcal sees it: width_n x height_n corners, `spacing`
// apart, corner (i, j) at origin + spacing * (i, j, 0).
struct BoardGrid {
  int width_n = 0;
  int height_n = 0;
  double spacing = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
};

// Infers the grid from the views' target points. Throws InputError when the
// points are not on one planar square grid (mrcal takes chessboards only).
BoardGrid InferBoardGrid(const std::vector<CalibrationView>& views);

// The views as mrcal's board observations, one frame each: the frame at
// cam_from_target[v] moved to the grid's first corner, the corners in
// mrcal's pixels with weight 1, the grid's other corners weight -1 (mrcal's
// "not used"). With `pool_to_point`, for each frame and grid corner the
// index of the view's point, -1 where the view has none. Throws InputError
// for a point off the grid.
MrcalBoardSolve MrcalBoardSolveOf(const std::vector<CalibrationView>& views,
                                  const std::vector<Rigid3d>& cam_from_target,
                                  const BoardGrid& grid,
                                  std::vector<std::vector<int>>* pool_to_point = nullptr);

struct MrcalCalibrationResult {
  std::string lensmodel;               // e.g. LENSMODEL_OPENCV4
  Camera camera;                       // mrcal's solution as the equivalent COLMAP camera
  std::vector<double> params_std_dev;  // in camera.params' order
  Eigen::MatrixXd params_covariance;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();  // metres (x2, y2)
  Eigen::Vector2d board_warp_std_dev = Eigen::Vector2d::Zero();
  double rms_px = 0;             // over inlier corners (per corner, 2-D)
  double residual_sigma_px = 0;  // per coordinate, dof-corrected
  int num_points = 0;            // corners observed
  int num_outliers = 0;          // corners mrcal rejected
  // Per view (in input order): the corners mrcal rejected, as indices into
  // that view's pixels.
  std::vector<std::vector<int>> outliers;
};

// `seed` gives the model (mapped to mrcal's) and the starting intrinsics,
// `seed_cam_from_target` one pose per view. Throws InputError for a model
// mrcal cannot express, NumericalError when mrcal fails.
MrcalCalibrationResult CalibrateWithMrcal(const std::vector<CalibrationView>& views,
                                          const Camera& seed,
                                          const std::vector<Rigid3d>& seed_cam_from_target,
                                          const MrcalCalibrationOptions& options);

}  // namespace portcal
