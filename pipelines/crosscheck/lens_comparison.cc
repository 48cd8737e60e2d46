#include "pipelines/crosscheck/lens_comparison.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

namespace {

const char* kMrcalParamNames[] = {"fx", "fy", "cx", "cy", "k1", "k2",
                                  "p1", "p2", "k3", "k4", "k5", "k6"};

}  // namespace

std::vector<ParameterComparison> CompareParameters(const Camera& portcal,
                                                   const std::vector<double>& portcal_std_dev,
                                                   const MrcalCalibrationResult& mrcal) {
  const std::vector<int> sources = MrcalParamSources(portcal.ModelName());
  std::vector<ParameterComparison> out;
  for (size_t i = 0; i < sources.size(); ++i) {
    ParameterComparison p;
    p.name = kMrcalParamNames[i];
    const int s = sources[i];
    p.portcal = s >= 0 ? portcal.params[s] : 0.0;
    // -1: undetermined by portcal's views (rank-deficient covariance).
    p.portcal_std_dev =
        s >= 0 && s < static_cast<int>(portcal_std_dev.size()) ? portcal_std_dev[s] : 0.0;
    p.mrcal = mrcal.camera.params[i];
    p.mrcal_std_dev = mrcal.params_std_dev[i];
    const double combined = std::hypot(std::max(0.0, p.portcal_std_dev), p.mrcal_std_dev);
    p.z = p.portcal_std_dev < 0 ? std::numeric_limits<double>::quiet_NaN()
          : combined > 0        ? (p.mrcal - p.portcal) / combined
                                : 0.0;
    out.push_back(p);
  }
  return out;
}

CalibratedLens LensOf(const CameraCalibrationResult& result) {
  return {result.camera, result.params_covariance};
}

CalibratedLens LensOf(const MrcalCalibrationResult& result) {
  return {result.camera, result.params_covariance};
}

std::vector<Rigid3d> Poses(const CameraCalibrationResult& result) {
  std::vector<Rigid3d> poses;
  for (const CalibratedView& view : result.views) poses.push_back(view.cam_from_target);
  return poses;
}

bool WarpSignificant(const MrcalCalibrationResult& mrcal) {
  for (int i = 0; i < 2; ++i) {
    if (mrcal.board_warp_std_dev[i] > 0 &&
        std::abs(mrcal.board_warp[i]) > 3 * mrcal.board_warp_std_dev[i]) {
      return true;
    }
  }
  return false;
}

CrossValidation CrossValidate(const std::vector<CalibrationView>& views, const Camera& initial,
                              const CameraCalibrationSettings& settings, int folds, int gridn_width,
                              const std::string& description,
                              const std::filesystem::path& heat_map) {
  const int k = folds;
  std::vector<std::vector<CalibrationView>> subsets(k);
  for (size_t v = 0; v < views.size(); ++v) subsets[v % k].push_back(views[v]);
  std::vector<CameraCalibrationResult> fits;
  CameraCalibrationSettings fold_settings = settings;
  fold_settings.initialize_from_data = true;  // each fold on its own
  for (int f = 0; f < k; ++f) {
    if (subsets[f].size() < 3) {
      throw InputError("--CrossCheck.folds " + std::to_string(k) + ": fold " + std::to_string(f) +
                       " gets " + std::to_string(subsets[f].size()) + " of " +
                       std::to_string(views.size()) + " views; at least 3 per fold are needed");
    }
    fits.push_back(CalibrateCamera(subsets[f], initial, fold_settings));
    LOG(INFO) << "cross_check: fold " << f << " (" << subsets[f].size() << " views, " << description
              << "): RMS " << fits.back().overall_rms_px << " px";
  }
  ProjectionDiffOptions diff_options;
  diff_options.gridn_width = gridn_width;
  CrossValidation out;
  out.settings = description;
  for (int a = 0; a < k; ++a) {
    for (int b = a + 1; b < k; ++b) {
      const ProjectionDiff diff =
          ComputeProjectionDiff(LensOf(fits[a]), LensOf(fits[b]), diff_options);
      FoldComparison fold;
      fold.fold_a = a;
      fold.fold_b = b;
      fold.views_a = static_cast<int>(subsets[a].size());
      fold.views_b = static_cast<int>(subsets[b].size());
      fold.mean_px = diff.mean_px;
      fold.p95_px = diff.p95_px;
      fold.predicted_mean_px = diff.predicted_mean_px;
      fold.predicted_p95_px = diff.predicted_p95_px;
      out.pairs.push_back(fold);
      if (diff.predicted_p95_px > 0)
        out.worst_ratio = std::max(out.worst_ratio, diff.p95_px / diff.predicted_p95_px);
      if (a == 0 && b == 1) {
        WriteProjectionDiffHeatMap(diff, static_cast<int>(initial.width),
                                   static_cast<int>(initial.height),
                                   "fold 0 vs fold 1, " + description, heat_map);
      }
    }
  }
  // The differences of independent fits scatter like a chi distribution
  // around the prediction; beyond twice the prediction the spread is not
  // noise.
  out.verdict =
      out.worst_ratio <= 2.0
          ? "consistent: the folds differ by what their uncertainty predicts (worst ratio " +
                FormatFixed(out.worst_ratio, 2) + ")"
          : "NOT consistent: the folds differ by up to " + FormatFixed(out.worst_ratio, 2) +
                "x what their uncertainty predicts; the lens model is too lean for this lens, "
                "or the data carry a systematic error (board warp, outliers, rolling shutter)";
  return out;
}

}  // namespace portcal
