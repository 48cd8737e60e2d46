#include "pipelines/calibration/held_out_evaluation.h"

#include <cmath>
#include <limits>

#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/util/error.h"
#include "pipelines/calibration/view_pose.h"

namespace portcal {
namespace {

constexpr int kGridCols = 16, kGridRows = 9;

// Each cell's mean residual and the RMS of those means.
void ResidualPattern(const std::vector<CalibrationView>& views, const HousedCamera& camera,
                     HeldOutEvaluation* evaluation) {
  Eigen::MatrixXd sum_x = Eigen::MatrixXd::Zero(kGridRows, kGridCols), sum_y = sum_x,
                  sum_squares_xy = sum_x;
  Eigen::MatrixXi count = Eigen::MatrixXi::Zero(kGridRows, kGridCols);
  const double width = camera.camera.width, height = camera.camera.height;
  for (size_t v = 0; v < views.size(); ++v) {
    const ViewEvaluation& view = evaluation->views[v];
    if (!view.evaluated) continue;
    for (size_t i = 0; i < views[v].pixels.size(); ++i) {
      const auto predicted = camera.Project(view.cam_from_target * views[v].points_in_target[i]);
      if (!predicted) continue;
      const Eigen::Vector2d& observed = views[v].pixels[i];
      const int c =
          std::clamp(static_cast<int>(observed.x() / width * kGridCols), 0, kGridCols - 1);
      const int r =
          std::clamp(static_cast<int>(observed.y() / height * kGridRows), 0, kGridRows - 1);
      const Eigen::Vector2d residual = observed - *predicted;
      sum_x(r, c) += residual.x();
      sum_y(r, c) += residual.y();
      sum_squares_xy(r, c) += residual.squaredNorm();
      ++count(r, c);
    }
  }
  evaluation->cell_points = count;
  evaluation->mean_residual_x.setConstant(kGridRows, kGridCols,
                                          std::numeric_limits<double>::quiet_NaN());
  evaluation->mean_residual_y = evaluation->mean_residual_x;
  double sum_squares = 0, floor_squares = 0;
  int cells = 0;
  for (int r = 0; r < kGridRows; ++r) {
    for (int c = 0; c < kGridCols; ++c) {
      if (count(r, c) < HeldOutEvaluation::kMinCellPoints) continue;
      const double mx = sum_x(r, c) / count(r, c), my = sum_y(r, c) / count(r, c);
      evaluation->mean_residual_x(r, c) = mx;
      evaluation->mean_residual_y(r, c) = my;
      sum_squares += mx * mx + my * my;
      // Noise alone: the mean of n residuals scattered with variance s^2
      // about it (both axes, s from the cell's own scatter, so a pattern
      // does not raise its own yardstick) has a squared length of s^2 / n.
      const int n = count(r, c);
      const double scatter =
          std::max(0.0, sum_squares_xy(r, c) - n * (mx * mx + my * my)) / (n - 1);
      floor_squares += scatter / n;
      ++cells;
    }
  }
  evaluation->systematic_px = cells > 0 ? std::sqrt(sum_squares / cells) : 0;
  evaluation->noise_floor_px = cells > 0 ? std::sqrt(floor_squares / cells) : 0;
}

}  // namespace

std::vector<CalibrationView> WithBoardSag(const std::vector<CalibrationView>& views,
                                          const Eigen::Vector2d& warp) {
  // The extent over these views: a board seen whole in any of them spans
  // it, as it did in the calibration.
  const Eigen::Vector4d extent = BoardExtent(views);
  std::vector<CalibrationView> sagged = views;
  for (CalibrationView& view : sagged) {
    for (Eigen::Vector3d& point : view.points_in_target)
      point.z() += BoardSag(warp.data(), BoardWarpUv(point, extent));
  }
  return sagged;
}

HeldOutEvaluation EvaluateHeldOut(const std::vector<CalibrationView>& views,
                                  const HousedCamera& camera, int num_threads) {
  HeldOutEvaluation evaluation;
  double sum_squares = 0;
  for (const CalibrationView& view : views) {
    ViewEvaluation result;
    result.image_name = view.image_name;
    result.num_points = static_cast<int>(view.pixels.size());
    try {
      result.cam_from_target = EstimateViewPose(view, camera, num_threads);
      result.rms_px = ViewRms(view, camera, result.cam_from_target);
      result.evaluated = std::isfinite(result.rms_px);
      if (!result.evaluated) result.why = "the residuals are not finite at the pose found";
    } catch (const NumericalError& e) {
      result.why = e.what();
    }
    if (result.evaluated) {
      sum_squares += result.rms_px * result.rms_px * result.num_points;
      evaluation.num_points += result.num_points;
    }
    evaluation.views.push_back(result);
  }
  if (evaluation.num_points == 0) {
    throw NumericalError(
        "held-out evaluation: no view could be evaluated (no pose fits any of the " +
        std::to_string(views.size()) + " views with this calibration)");
  }
  evaluation.rms_px = std::sqrt(sum_squares / evaluation.num_points);
  ResidualPattern(views, camera, &evaluation);
  return evaluation;
}

std::vector<FoldEvaluation> CrossValidate(const std::vector<CalibrationView>& views, int folds,
                                          const CalibrationMethod& calibrate, int num_threads) {
  if (folds < 2 || folds > static_cast<int>(views.size())) {
    throw OptionError("--Evaluation.folds", folds,
                      "between 2 and the number of views (" + std::to_string(views.size()) + ")");
  }
  std::vector<FoldEvaluation> result;
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<CalibrationView> train, test;
    for (size_t v = 0; v < views.size(); ++v) {
      (static_cast<int>(v % folds) == fold ? test : train).push_back(views[v]);
    }
    FoldEvaluation evaluation;
    evaluation.fold = fold;
    evaluation.num_train = static_cast<int>(train.size());
    evaluation.num_test = static_cast<int>(test.size());
    const HousedCamera fitted = calibrate(train, &evaluation.train_rms_px);
    const HeldOutEvaluation held_out = EvaluateHeldOut(test, fitted, num_threads);
    evaluation.test_rms_px = held_out.rms_px;
    evaluation.num_test_points = held_out.num_points;
    result.push_back(evaluation);
  }
  return result;
}

}  // namespace portcal
