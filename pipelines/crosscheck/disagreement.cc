#include "pipelines/crosscheck/disagreement.h"

#include <algorithm>

#include "colmap_ext/util/string_utils.h"
#include "pipelines/crosscheck/lens_comparison.h"

namespace portcal {

void NoteResolveDifference(const Camera& input, const Camera& resolved,
                           const ProjectionDiffOptions& diff_options, CrossCheckResult* result) {
  ProjectionDiffOptions plain = diff_options;
  plain.focus_radius = 1e9;  // the whole imager, unweighted
  const ProjectionDiff resolve = ComputeProjectionDiff({input, {}}, {resolved, {}}, plain);
  if (resolve.mean_px > 0.01) {
    result->causes.push_back(
        "the input calibration is not portcal's solution of these observations (re-solving "
        "from it moves the projection by " +
        FormatFixed(resolve.mean_px, 3) + " px on average): made from other views or settings?");
  }
}

void NoteMrcalSolution(const std::vector<CalibrationView>& views,
                       const MrcalCalibrationResult& mrcal, CrossCheckResult* result) {
  result->num_points = mrcal.num_points;
  result->mrcal_rms_px = mrcal.rms_px;
  result->mrcal_outliers = mrcal.num_outliers;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!mrcal.outliers[v].empty()) {
      result->mrcal_outliers_per_view.emplace_back(views[v].image_name,
                                                   static_cast<int>(mrcal.outliers[v].size()));
    }
  }
  result->mrcal_warp = mrcal.board_warp;
  result->mrcal_warp_std_dev = mrcal.board_warp_std_dev;
}

void ExplainDisagreement(const CalibrationReport& input, const std::string& lensmodel,
                         const MrcalCalibrationResult& mrcal, bool warp_cause, bool outlier_cause,
                         bool mrcal_regularization, CrossCheckResult* result) {
  if (warp_cause) {
    result->causes.push_back(
        "board warp: mrcal finds the board bent by x " +
        FormatFixed(mrcal.board_warp.x() * 1e3, 2) + " +- " +
        FormatFixed(mrcal.board_warp_std_dev.x() * 1e3, 2) + " mm, y " +
        FormatFixed(mrcal.board_warp.y() * 1e3, 2) + " +- " +
        FormatFixed(mrcal.board_warp_std_dev.y() * 1e3, 2) +
        " mm, portcal holds it flat (camera_calibrator --Calibration.estimate_board_warp 1)");
  }
  if (outlier_cause) {
    result->causes.push_back("outliers: mrcal rejected " + std::to_string(mrcal.num_outliers) +
                             " corners in " +
                             std::to_string(result->mrcal_outliers_per_view.size()) +
                             " views; portcal fits every corner");
  }
  const std::string freedom = MrcalExtraFreedom(input.camera.ModelName());
  if (!freedom.empty()) {
    result->causes.push_back("parameterisation: mrcal's " + lensmodel + " frees " + freedom +
                             ", which " + input.camera.ModelName() + " holds");
  }
  if (mrcal_regularization) {
    result->causes.push_back(
        "regularisation: mrcal pulls the distortions and the principal point "
        "weakly towards zero and the centre (a small bias by design)");
  }
}

std::vector<CalibrationView> RerunAsMrcal(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const MrcalCalibrationResult& mrcal,
                                          bool outlier_cause,
                                          const ProjectionDiffOptions& diff_options,
                                          const std::filesystem::path& dir,
                                          CameraCalibrationSettings* rerun_settings,
                                          CrossCheckResult* result) {
  std::vector<CalibrationView> rerun_views = views;
  rerun_settings->estimate_board_warp = true;
  if (outlier_cause) {
    for (size_t v = 0; v < views.size(); ++v) {
      std::vector<int> drop = mrcal.outliers[v];
      std::sort(drop.rbegin(), drop.rend());
      for (const int i : drop) {
        rerun_views[v].pixels.erase(rerun_views[v].pixels.begin() + i);
        rerun_views[v].points_in_target.erase(rerun_views[v].points_in_target.begin() + i);
      }
    }
  }
  result->rerun_description = std::string("portcal with board warp") +
                              (outlier_cause ? " and without mrcal's outlier corners" : "");
  const CameraCalibrationResult rerun = CalibrateCamera(rerun_views, camera, *rerun_settings);
  result->rerun_diff = ComputeProjectionDiff(LensOf(rerun), LensOf(mrcal), diff_options);
  result->rerun_parameters = CompareParameters(rerun.camera, rerun.params_std_dev, mrcal);
  WriteProjectionDiffHeatMap(*result->rerun_diff, static_cast<int>(camera.width),
                             static_cast<int>(camera.height), "portcal (re-run) vs mrcal",
                             dir / "projection_diff_rerun.png");
  return rerun_views;
}

}  // namespace portcal
