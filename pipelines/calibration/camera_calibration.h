// Camera intrinsics from views of a planar target: Zhang's closed form,
// then Ceres over intrinsics and poses (any COLMAP model, any parameter
// subset fixed), optional board warp (mrcal's two-parameter parabolic sag),
// outlier views, and standard deviations from the covariance scaled by the
// residual variance.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct CalibrationView {
  std::string image_name;
  std::vector<Eigen::Vector3d> points_in_target;  // metres, z = 0 for a flat board
  std::vector<Eigen::Vector2d> pixels;            // COLMAP pixels
};

struct CameraCalibrationSettings {
  // Parameters held at their initial value: names of the model's parameters
  // (e.g. "k2", "p1"), or "focal", "principal_point", "extra".
  std::vector<std::string> fixed_params;
  // Initialize focal length and principal point from the data (Zhang), not
  // from the initial camera.
  bool initialize_from_data = true;
  // mrcal's board deformation: z = wx (1 - u^2) + wy (1 - v^2), u, v in
  // [-1, 1] across the board.
  bool estimate_board_warp = false;
  // A view whose RMS exceeds factor x the median RMS is an outlier; with
  // drop_outlier_views it is removed and the rest re-solved.
  double outlier_view_factor = 3.0;
  bool drop_outlier_views = false;
  int min_points_per_view = 6;
  int max_num_iterations = 200;
  int num_threads = 2;
  void Check() const;  // throws OptionError
};

struct CalibratedView {
  std::string image_name;
  Rigid3d cam_from_target;
  double rms_px = 0;
  int num_points = 0;
  bool outlier = false;  // RMS > outlier_view_factor x median
  bool dropped = false;  // removed from the final solve
};

struct CameraCalibrationResult {
  Camera camera;
  std::vector<double> params_std_dev;  // 0 for fixed parameters, -1 undetermined
  // Full covariance of camera.params (px^2 ...), the residual variance
  // applied; zero rows and columns for fixed parameters, all zero when the
  // system is rank deficient.
  Eigen::MatrixXd params_covariance;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();  // metres
  Eigen::Vector2d board_warp_std_dev = Eigen::Vector2d::Zero();
  double overall_rms_px = 0;     // over all points of the kept views
  double residual_sigma_px = 0;  // sqrt(sum r^2 / (2N - free parameters))
  int num_points = 0;
  std::vector<CalibratedView> views;
};

// The board's extent (x min, x max, y min, y max) over the views' target
// points: where board_warp.h's (u, v) run from -1 to 1. ExtendBoardExtent
// grows one by a view's points (start from BoardExtent({})).
Eigen::Vector4d BoardExtent(const std::vector<CalibrationView>& views);
void ExtendBoardExtent(const CalibrationView& view, Eigen::Vector4d* extent);

// Indices of the parameters that `names` hold (CameraCalibrationSettings::
// fixed_params). Throws OptionError for a name the model does not have.
std::vector<int> FixedParamIndices(const Camera& camera, const std::vector<std::string>& names);

// `initial` gives the model, image size and starting (or fixed) values.
// Throws NumericalError when too few views remain or the solve fails.
CameraCalibrationResult CalibrateCamera(const std::vector<CalibrationView>& views,
                                        const Camera& initial,
                                        const CameraCalibrationSettings& settings);

}  // namespace portcal
