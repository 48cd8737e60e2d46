#include "pipelines/guidance/live_estimator.h"

#include <iomanip>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/calibration/stereo_calibration.h"
#include "pipelines/calibration/view_pose.h"

namespace portcal {

void LiveEstimatorOptions::Check() const {
  camera.Validate("--ImageReader.camera_model / --input_calibration");
  if (housing) housing->ValidateInput("--Housing.params");
  guidance.Check();
  if (!(prior_pixel_sigma_px > 0)) {
    throw OptionError("prior pixel sigma", prior_pixel_sigma_px, "> 0 px");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

std::string LiveEstimate::Summary() const {
  if (!camera2) return CameraSummary();
  std::ostringstream out;
  out << "camera 1, " << CameraSummary() << "\ncamera 2, " << camera2->CameraSummary() << "\nrig: ";
  if (rig && rig->solved) {
    const double sigma = rig->translation_std_dev.norm();
    out << std::setprecision(4) << "baseline " << 1000 * rig->cam2_from_cam1.translation.norm()
        << " mm ± " << std::setprecision(2) << 1000 * sigma << " mm, rotation σ "
        << rig->rotation_std_dev_deg.maxCoeff() << " deg, RMS " << std::setprecision(3)
        << rig->rms_px << " px";
  } else {
    out << (rig ? rig->status : std::string("not estimated"));
  }
  return out.str();
}

std::string LiveEstimate::CameraSummary() const {
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
  if (!options.HousingCalibration())
    fixed_indices_ = FixedParamIndices(options.camera, options.fixed_params);
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
  for (const CalibratedView& view : result.views)
    estimate->view_poses.push_back(view.cam_from_target);
}

}  // namespace

void LiveEstimator::Solve(const std::vector<CalibrationView>& views, LiveEstimate* estimate) const {
  const int needed = options_.MinViews() - static_cast<int>(views.size());
  if (needed > 0) {
    estimate->status = std::to_string(needed) + " more view" + (needed == 1 ? "" : "s") +
                       " before the first estimate";
    return;
  }
  try {
    if (options_.HousingCalibration()) {
      HousingCalibrationSettings settings;
      settings.estimate_board_warp = options_.estimate_board_warp;
      settings.num_threads = options_.num_threads;
      const HousingCalibrationResult result =
          CalibrateHousing(views, estimate->camera.camera, *estimate->camera.housing, settings);
      estimate->camera.housing = result.housing;
      TakeSolve(result, result.housing.ParamsInfo(), result.housing.params, result.housing_std_dev,
                estimate);
      if (const auto why = result.housing.Implausibility())
        estimate->status = "implausible housing: " + *why;
    } else {
      CameraCalibrationSettings settings;
      settings.fixed_params = options_.fixed_params;
      settings.estimate_board_warp = options_.estimate_board_warp;
      settings.num_threads = options_.num_threads;
      const CameraCalibrationResult result =
          CalibrateCamera(views, estimate->camera.camera, settings);
      estimate->camera.camera = result.camera;
      TakeSolve(result, result.camera.ParamsInfo(), result.camera.params, result.params_std_dev,
                estimate);
    }
    estimate->solved = true;
  } catch (const NumericalError& e) {
    estimate->status = std::string("no estimate: ") + e.what();
  } catch (const InputError& e) {
    estimate->status = std::string("no estimate: ") + e.what();
  }
}

LiveEstimate LiveEstimator::EstimateCamera(const std::vector<CalibrationView>& views,
                                           const LiveEstimate* previous) const {
  LiveEstimate estimate;
  estimate.num_views = static_cast<int>(views.size());
  estimate.camera = previous && previous->solved ? previous->camera
                                                 : HousedCamera{options_.camera, options_.housing};
  Solve(views, &estimate);
  const CalibrationUnknowns unknowns = Unknowns(estimate.camera);
  const int p = unknowns.NumUnknowns();
  estimate.information = CalibrationInformation::Zero(p);
  if (estimate.solved && estimate.view_poses.size() == views.size()) {
    for (size_t v = 0; v < views.size(); ++v) {
      estimate.information +=
          ViewInformation(unknowns, views[v].points_in_target, estimate.view_poses[v]);
    }
  }
  if (!estimate.solved) estimate.pixel_sigma_px = options_.prior_pixel_sigma_px;
  NextPoseOptions guidance = options_.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, estimate.pixel_sigma_px);
  estimate.uncertainty =
      ProjectionUncertaintyModel(unknowns, guidance.Uncertainty()).Evaluate(estimate.information);
  return estimate;
}

LiveEstimate LiveEstimator::Estimate(const std::vector<CalibrationView>& views,
                                     const LiveEstimate* previous) const {
  LiveEstimate estimate = EstimateCamera(views, previous);
  NextPoseOptions guidance = options_.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, estimate.pixel_sigma_px);
  try {
    estimate.next = SuggestPoses(Unknowns(estimate.camera), target_, estimate.information,
                                 estimate.num_views, 1, guidance)[0];
  } catch (const NumericalError& e) {
    estimate.suggestion_error = e.what();
  }
  return estimate;
}

namespace {

LiveRig SolveRig(const std::vector<CalibrationView>& views1,
                 const std::vector<CalibrationView>& views2, const LiveEstimate& camera1,
                 const LiveEstimate& camera2, int num_threads) {
  LiveRig rig;
  if (!camera1.solved || !camera2.solved) {
    rig.status = "the relative pose once both cameras are estimated";
    return rig;
  }
  std::vector<StereoFrame> frames;
  for (size_t i = 0; i < views1.size(); ++i) frames.push_back({views1[i], views2[i]});
  StereoCalibrationSettings settings;
  settings.num_threads = num_threads;
  try {
    const StereoCalibrationResult result =
        CalibrateStereo(frames, camera1.camera, camera2.camera, settings);
    rig.solved = true;
    rig.cam2_from_cam1 = result.cam2_from_cam1;
    rig.rotation_std_dev_deg = result.rotation_std_dev_deg;
    rig.translation_std_dev = result.translation_std_dev;
    rig.rms_px = result.overall_rms_px;
  } catch (const NumericalError& e) {
    rig.status = std::string("no relative pose: ") + e.what();
  } catch (const InputError& e) {
    rig.status = std::string("no relative pose: ") + e.what();
  }
  return rig;
}

}  // namespace

LiveEstimate EstimateRig(const LiveEstimator& camera1, const LiveEstimator& camera2,
                         const std::vector<CalibrationView>& views1,
                         const std::vector<CalibrationView>& views2, const LiveEstimate* previous) {
  if (views1.size() != views2.size())
    throw std::logic_error("EstimateRig: views1 and views2 differ in number");
  LiveEstimate estimate = camera1.EstimateCamera(views1, previous);
  LiveEstimate estimate2 =
      camera2.EstimateCamera(views2, previous ? previous->camera2.get() : nullptr);
  estimate.rig = SolveRig(views1, views2, estimate, estimate2, camera1.num_threads());
  NextPoseOptions guidance = camera1.guidance();
  guidance.uncertainty.pixel_sigma_px =
      std::max({0.02, estimate.pixel_sigma_px, estimate2.pixel_sigma_px});
  try {
    if (estimate.rig->solved) {
      const RigUnknowns rig{camera1.Unknowns(estimate.camera), camera2.Unknowns(estimate2.camera),
                            estimate.rig->cam2_from_cam1};
      estimate.next = SuggestRigPose(rig, camera1.target(), estimate.information,
                                     estimate2.information, estimate.num_views, guidance);
    } else {
      estimate.next = SuggestPoses(camera1.Unknowns(estimate.camera), camera1.target(),
                                   estimate.information, estimate.num_views, 1, guidance)[0];
    }
  } catch (const NumericalError& e) {
    estimate.suggestion_error = e.what();
  }
  if (estimate.next && estimate.rig->solved) {
    estimate2.next = *estimate.next;
    estimate2.next->cam_from_target = estimate.rig->cam2_from_cam1 * estimate.next->cam_from_target;
  }
  estimate.camera2 = std::make_shared<const LiveEstimate>(std::move(estimate2));
  return estimate;
}

double RigGain(const LiveEstimator& camera1, const LiveEstimator& camera2,
               const LiveEstimate& estimate, const CalibrationView& view1,
               const CalibrationView& view2) {
  const double gain1 = camera1.Gain(estimate, view1);
  return estimate.camera2 ? std::max(gain1, camera2.Gain(*estimate.camera2, view2)) : gain1;
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
  const CalibrationInformation added = ViewInformation(unknowns, view.points_in_target, pose);
  NextPoseOptions guidance = options_.guidance;
  guidance.uncertainty.pixel_sigma_px = std::max(0.02, estimate.pixel_sigma_px);
  // Judged both on mean-frames as the page will show it (the new view's
  // frame joins the average) and over the kept views' frames only: a frame
  // added to the average (a far, small board) can raise the figure while
  // the intrinsics are better known (the real in-air views: 0.373 -> 0.389
  // px with a view that lowers it to 0.368 px over the kept frames).
  const ProjectionUncertaintyModel model(unknowns, guidance.Uncertainty());
  CalibrationInformation over_kept_frames = estimate.information;
  over_kept_frames.reduced += added.reduced;
  const ProjectionUncertainty after = model.Evaluate(estimate.information + added);
  const ProjectionUncertainty after_kept = model.Evaluate(over_kept_frames);
  if (!estimate.uncertainty.determined) return added.reduced.trace() > 0 ? 1 : 0;
  if (!after.determined || !after_kept.determined || !(estimate.uncertainty.mean_px > 0)) return 0;
  return std::max({0.0, 1 - after.mean_px / estimate.uncertainty.mean_px,
                   1 - after_kept.mean_px / estimate.uncertainty.mean_px});
}

TargetShape ShapeOfTarget(const TargetDetectorOptions& detector) {
  std::vector<Eigen::Vector3d> points;
  for (const BoardPoint& p : TargetLayout(detector)) points.push_back(p.point_in_target);
  return TargetShape::FromPoints(points);
}

}  // namespace portcal
