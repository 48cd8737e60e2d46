// Judging a calibration on views it was not fitted to: each view's pose
// estimated alone with the calibration fixed (lens and housing), its
// residuals, and their pattern over the image (a systematic error shows as
// a mean residual that varies smoothly over the image, noise does not).
// K-fold cross-validation repeats this for a calibration method on one set
// of views.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "pipelines/calibration/camera_calibration.h"

namespace portcal {

struct ViewEvaluation {
  std::string image_name;
  bool evaluated = false;  // false: no pose fits the view (`why`)
  std::string why;
  Rigid3d cam_from_target;
  double rms_px = 0;
  int num_points = 0;
};

struct HeldOutEvaluation {
  std::vector<ViewEvaluation> views;
  double rms_px = 0;  // over every point of the evaluated views
  int num_points = 0;
  // The residuals' pattern: their mean (observed - predicted, px) in each
  // cell of a 16 x 9 grid over the image (NaN where fewer than
  // kMinCellPoints fall), and the RMS length of those means over the cells:
  // near noise_floor_px (what each cell's scatter about its mean gives an
  // average of its points) for noise alone, larger when the model is wrong
  // somewhere in the image. A wrong model widens the scatter too (each
  // view's pose absorbs its error differently), so compare with a
  // calibration known good where one is at hand.
  static constexpr int kMinCellPoints = 5;
  Eigen::MatrixXd mean_residual_x, mean_residual_y;
  Eigen::MatrixXi cell_points;
  double systematic_px = 0;
  double noise_floor_px = 0;  // what systematic_px would be for noise alone
};

// The views with their target points moved along the board's normal by
// the sag `warp` (mrcal's parabolic warp, colmap_ext/cost/board_warp.h)
// over the views' extent: a calibration that fitted its board's warp is
// judged on the same board, warped alike, not on a flat one.
std::vector<CalibrationView> WithBoardSag(const std::vector<CalibrationView>& views,
                                          const Eigen::Vector2d& warp);

// Throws NumericalError when no view can be evaluated.
HeldOutEvaluation EvaluateHeldOut(const std::vector<CalibrationView>& views,
                                  const HousedCamera& camera, int num_threads);

// One fold of a cross-validation: calibrated on the other folds' views,
// evaluated on this one's.
struct FoldEvaluation {
  int fold = 0;
  int num_train = 0, num_test = 0;
  double train_rms_px = 0;  // the fit's own RMS
  double test_rms_px = 0;   // held out
  int num_test_points = 0;  // of the held-out views evaluated
};

// Fits a calibration to views (a camera or a housing calibration) and
// returns it with its own RMS.
using CalibrationMethod =
    std::function<HousedCamera(const std::vector<CalibrationView>& views, double* rms_px)>;

// Views go to folds in turn (view i to fold i mod K), so that a capture's
// beginning and end are both in every fold. Throws OptionError for K < 2
// or more folds than views.
std::vector<FoldEvaluation> CrossValidate(const std::vector<CalibrationView>& views, int folds,
                                          const CalibrationMethod& calibrate, int num_threads);

}  // namespace portcal
