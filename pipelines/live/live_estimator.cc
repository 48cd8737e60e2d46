#include "pipelines/live/live_estimator.h"

#include <iomanip>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/view_pose.h"

namespace portcal {

void LiveEstimatorOptions::Check() const {
  camera.Validate("--ImageReader.camera_model / --input_calibration");
  if (housing) housing->ValidateInput("--Housing.params");
  guidance.Check();
  if (!(prior_pixel_sigma_px > 0)) {
    throw OptionError("prior pixel sigma", std::to_string(prior_pixel_sigma_px), "> 0 px");
  }
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
}

std::string LiveEstimate::Summary() const {
  std::ostringstream out;
  out << num_views << (num_views == 1 ? " view" : " views");
  if (!solved) {
    out << ": " << status;
    return out.str();
  }
  out << std::setprecision(4) << ":";
  for (size_t k = 0; k < names.size(); ++k) {
    if (std_devs[k] == 0) continue;  // held
    out << (k ? ", " : " ") << names[k] << " " << values[k];
    if (std_devs[k] > 0) {
      out << " ± " << std::setprecision(2) << std_devs[k] << std::setprecision(4);
    } else {
      out << " (undetermined)";
    }
  }
  out << std::setprecision(3) << "; RMS " << rms_px << " px; projection uncertainty ";
  if (uncertainty.determined) {
    out << uncertainty.mean_px << " px (max " << uncertainty.max_px << " px)";
  } else {
    out << "undetermined";
  }
  if (!status.empty()) out << "; " << status;
  return out.str();
}

LiveEstimator::LiveEstimator(const LiveEstimatorOptions& options, const TargetShape& target)
    : options_(options), target_(target) {
  options.Check();
  if (!options.HousingCalibration()) fixed_indices_ = FixedParamIndices(options.camera, options.fixed_params);
}

CalibrationUnknowns LiveEstimator::Unknowns(const HousedCamera& camera) const {
  CalibrationUnknowns unknowns;
  unknowns.camera = camera;
  unknowns.housing_calibration = options_.HousingCalibration();
  unknowns.fixed_intrinsics = fixed_indices_;
  return unknowns;
}

namespace {

// What a camera or housing calibration says that the estimate shows: the
// estimated parameters by name with their deviations, the fit, the poses.
template <typename Result>
void TakeSolve(const Result& result, const std::string& names, const std::vector<double>& values,
               const std::vector<double>& std_devs, LiveEstimate* estimate) {
  estimate->names = SplitTokens(names, ", ");
  estimate->values = values;
  estimate->std_devs = std_devs;
  estimate->rms_px = result.overall_rms_px;
  estimate->pixel_sigma_px = result.residual_sigma_px;
  for (const CalibratedView& view : result.views) estimate->view_poses.push_back(view.cam_from_target);
}

}  // namespace

void LiveEstimator::Solve(const std::vector<CalibrationView>& views, LiveEstimate* estimate) const {
  const int needed = options_.MinViews() - static_cast<int>(views.size());
  if (needed > 0) {
    estimate->status = std::to_string(needed) + " more view" + (needed == 1 ? "" : "s") + " before the first estimate";
    return;
  }
  try {
    if (options_.HousingCalibration()) {
      HousingCalibrationSettings settings;
      settings.num_threads = options_.num_threads;
      const HousingCalibrationResult result =
          CalibrateHousing(views, estimate->camera.camera, *estimate->camera.housing, settings);
      estimate->camera.housing = result.housing;
      TakeSolve(result, result.housing.ParamsInfo(), result.housing.params, result.housing_std_dev, estimate);
      if (const auto why = result.housing.Implausibility()) estimate->status = "implausible housing: " + *why;
    } else {
      CameraCalibrationSettings settings;
      settings.fixed_params = options_.fixed_params;
      settings.num_threads = options_.num_threads;
      const CameraCalibrationResult result = CalibrateCamera(views, estimate->camera.camera, settings);
      estimate->camera.camera = result.camera;
      TakeSolve(result, result.camera.ParamsInfo(), result.camera.params, result.params_std_dev, estimate);
    }
    estimate->solved = true;
  } catch (const NumericalError& e) {
    estimate->status = std::string("no estimate: ") + e.what();
  } catch (const InputError& e) {
    estimate->status = std::string("no estimate: ") + e.what();
  }
}

LiveEstimate LiveEstimator::Estimate(const std::vector<CalibrationView>& views, const LiveEstimate* previous) const {
  LiveEstimate estimate;
  estimate.num_views = static_cast<int>(views.size());
  estimate.camera = previous && previous->solved ? previous->camera : HousedCamera{options_.camera, options_.housing};
  Solve(views, &estimate);
  const CalibrationUnknowns unknowns = Unknowns(estimate.camera);
  const int p = unknowns.NumUnknowns();
  estimate.information = Eigen::MatrixXd::Zero(p, p);
  if (estimate.solved && estimate.view_poses.size() == views.size()) {
    for (size_t v = 0; v < views.size(); ++v) {
      estimate.information += ViewInformation(unknowns, views[v].points_in_target, estimate.view_poses[v]);
    }
  }
  if (!estimate.solved) estimate.pixel_sigma_px = options_.prior_pixel_sigma_px;
  NextPoseOptions guidance = options_.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, estimate.pixel_sigma_px);
  estimate.uncertainty = ProjectionUncertaintyModel(unknowns, guidance.Uncertainty()).Evaluate(estimate.information);
  try {
    estimate.next = SuggestPoses(unknowns, target_, estimate.information, estimate.num_views, 1, guidance)[0];
  } catch (const NumericalError& e) {
    estimate.suggestion_error = e.what();
  }
  return estimate;
}

double LiveEstimator::Gain(const LiveEstimate& estimate, const CalibrationView& view) const {
  if (!estimate.solved) return 1;
  const CalibrationUnknowns unknowns = Unknowns(estimate.camera);
  Rigid3d pose;
  try {
    pose = EstimateViewPose(view, estimate.camera, 1);
  } catch (const NumericalError&) {
    return 0;  // no pose fits this view: it would not help
  }
  const Eigen::MatrixXd added = ViewInformation(unknowns, view.points_in_target, pose);
  NextPoseOptions guidance = options_.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, estimate.pixel_sigma_px);
  const ProjectionUncertainty after =
      ProjectionUncertaintyModel(unknowns, guidance.Uncertainty()).Evaluate(estimate.information + added);
  if (!estimate.uncertainty.determined) return added.trace() > 0 ? 1 : 0;
  if (!after.determined || !(estimate.uncertainty.mean_px > 0)) return 0;
  return std::max(0.0, 1 - after.mean_px / estimate.uncertainty.mean_px);
}

}  // namespace portcal
