#include "pipelines/calibration/calibration_report.h"

#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

namespace {

// The names of the parameters whose standard deviation is undetermined
// (negative: the covariance is rank deficient there).
std::vector<std::string> UndeterminedNames(const std::vector<double>& std_dev,
                                           const std::string& params_info) {
  const std::vector<std::string> names = SplitTokens(params_info, ", ");
  std::vector<std::string> undetermined;
  for (size_t i = 0; i < std_dev.size() && i < names.size(); ++i) {
    if (std_dev[i] < 0) undetermined.push_back(names[i]);
  }
  return undetermined;
}

// A warning, first in the report, where the views leave parameters
// undetermined: the values may look fine (even a lower RMS) and mean
// nothing.
void WarnOfUndetermined(const std::vector<std::string>& names, const std::string& remedy,
                        CalibrationReport* report) {
  if (names.empty()) return;
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  report->warnings.push_back("the views do not determine " + list +
                             " (no finite standard deviation): their values mean nothing; " +
                             remedy);
}

}  // namespace

CalibrationReport ReportOf(const CameraCalibrationResult& result, bool with_board_warp,
                           const std::string& target) {
  CalibrationReport report;
  report.camera = result.camera;
  report.parameters_std_dev = result.params_std_dev;
  if (!result.params_covariance.isZero(0)) report.parameters_covariance = result.params_covariance;
  report.overall_rms_px = result.overall_rms_px;
  report.residual_sigma_px = result.residual_sigma_px;
  report.num_points = result.num_points;
  report.views = result.views;
  report.target_description = target;
  if (with_board_warp) {
    report.board_warp = result.board_warp;
    report.board_warp_std_dev = result.board_warp_std_dev;
  }
  WarnOfUndetermined(
      UndeterminedNames(result.params_std_dev, result.camera.ParamsInfo()),
      "hold them (--Calibration.fixed_params) or add views with more tilt and nearer the corners",
      &report);
  return report;
}

std::string BoardWarpNote(const CameraCalibrationResult& warped,
                          const CameraCalibrationResult& flat) {
  // A sag beyond this many standard deviations is significant.
  constexpr double kSignificantSigmas = 3.0;
  const Eigen::Vector2d& w = warped.board_warp;
  const Eigen::Vector2d& sd = warped.board_warp_std_dev;
  const auto in_sigmas = [](double value, double sigma) {
    return sigma > 0 ? std::abs(value) / sigma : 0.0;
  };
  const double z = std::max(in_sigmas(w.x(), sd.x()), in_sigmas(w.y(), sd.y()));
  std::ostringstream note;
  note << std::fixed << std::setprecision(3) << "board warp: sag x " << 1000 * w.x() << " +- "
       << 1000 * sd.x() << " mm, y " << 1000 * w.y() << " +- " << 1000 * sd.y() << " mm, "
       << (z > kSignificantSigmas ? "significant" : "not significant") << " ("
       << std::setprecision(1) << z << " sigma); held flat, ";
  // The focal length and principal point parameter that would move most,
  // in units of its standard deviation here.
  std::vector<int> indices = CameraModelFocalLengthIdxs(warped.camera.model_id);
  for (int i : CameraModelPrincipalPointIdxs(warped.camera.model_id)) indices.push_back(i);
  const std::vector<std::string> names = SplitTokens(warped.camera.ParamsInfo(), ", ");
  int worst = -1;
  double worst_z = -1;
  for (int i : indices) {
    const double sigma =
        i < static_cast<int>(warped.params_std_dev.size()) ? warped.params_std_dev[i] : 0;
    const double shift_z = in_sigmas(flat.camera.params[i] - warped.camera.params[i], sigma);
    if (shift_z > worst_z) {
      worst_z = shift_z;
      worst = i;
    }
  }
  note << names[static_cast<size_t>(worst)] << " would be " << std::setprecision(1)
       << flat.camera.params[static_cast<size_t>(worst)] << " px (" << std::showpos
       << flat.camera.params[static_cast<size_t>(worst)] -
              warped.camera.params[static_cast<size_t>(worst)]
       << std::noshowpos << " px, " << worst_z << " sigma), the RMS " << std::setprecision(3)
       << flat.overall_rms_px << " px instead of " << warped.overall_rms_px << " px";
  return note.str();
}

namespace {

// Which uncertainty the housing's standard deviations give.
std::string HousingUncertaintyNote(const HousingCalibrationResult& result) {
  std::ostringstream note;
  if (!result.in_air_views.empty()) {
    note << "joint solve with " << result.in_air_views.size() << " in-air views (RMS "
         << FormatFixed(result.in_air_rms_px, 3) << " px, residual sigma "
         << FormatFixed(result.in_air_residual_sigma_px, 3)
         << " px; each set weighted by its own): the intrinsics are refined by both sets, and the "
            "housing's "
            "standard deviations include their uncertainty";
    if (result.in_air_board_warp) {
      const Eigen::Vector2d sd = result.in_air_board_warp_std_dev.value_or(Eigen::Vector2d::Zero());
      note << "; the in-air views' own board warp: x "
           << FormatFixed(1000 * result.in_air_board_warp->x(), 3) << " +- "
           << FormatFixed(1000 * sd.x(), 3) << " mm, y "
           << FormatFixed(1000 * result.in_air_board_warp->y(), 3) << " +- "
           << FormatFixed(1000 * sd.y(), 3) << " mm (a board's sag differs between sessions)";
    }
  } else if (std::any_of(result.camera_std_dev.begin(), result.camera_std_dev.end(),
                         [](double s) { return s != 0; })) {
    note << "intrinsics refined from the underwater views alone; the standard deviations include "
            "their "
            "uncertainty";
  } else if (result.lens_covariance_propagated) {
    note << "the in-air intrinsics are held; their covariance (from the calibration file) is "
            "propagated into "
            "the housing's standard deviations to first order (how the port's estimate moves with "
            "the lens, "
            "times the lens's covariance). The joint solve (--in_air_database_path) also lets the "
            "underwater "
            "views refine the lens";
  } else {
    note << "the in-air intrinsics are taken as exact (the calibration file carries no "
            "covariance): the "
            "housing's standard deviations leave out their uncertainty and understate its error "
            "(give the "
            "in-air views, --in_air_database_path, for a joint solve)";
  }
  return note.str();
}

}  // namespace

CalibrationReport ReportOf(const HousingCalibrationResult& result, const std::string& target) {
  CalibrationReport report;
  report.camera = result.camera;
  report.parameters_std_dev = result.camera_std_dev;
  report.parameters_covariance = result.camera_covariance;
  report.housing = result.housing;
  report.housing_std_dev = result.housing_std_dev;
  report.housing_covariance = result.housing_covariance;
  report.overall_rms_px = result.overall_rms_px;
  report.residual_sigma_px = result.residual_sigma_px;
  report.num_points = result.num_points;
  report.views = result.views;
  report.target_description = target;
  if (result.board_warp_estimated) {
    report.board_warp = result.board_warp;
    report.board_warp_std_dev = result.board_warp_std_dev;
  }
  report.notes.push_back(HousingUncertaintyNote(result));
  std::vector<std::string> undetermined =
      UndeterminedNames(result.camera_std_dev, result.camera.ParamsInfo());
  for (const std::string& name :
       UndeterminedNames(result.housing_std_dev, result.housing.ParamsInfo())) {
    undetermined.push_back(name);
  }
  WarnOfUndetermined(
      undetermined,
      "hold the in-air intrinsics (--Calibration.refine_intrinsics 0), or add views with more tilt "
      "and nearer the image corners",
      &report);
  return report;
}

}  // namespace portcal
