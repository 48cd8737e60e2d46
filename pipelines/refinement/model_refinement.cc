#include "pipelines/refinement/model_refinement.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/bundle_adjustment/position_priors.h"
#include "pipelines/calibration/calibration_verdict.h"

namespace portcal {
namespace {

// |correlation| of an intrinsic with a housing parameter from which the
// report warns: the housing's standard deviation is then at least 3.2 times
// what it would be with the intrinsic known.
constexpr double kTradeOffCorrelation = 0.95;
// From this inflation of the housing's standard deviation by a trade-off
// (|rho| >= 0.995) the housing is hardly measured at all: a warning, not a
// note (own renders at 1920 x 1080, 30 views, OPENCV behind a dome 4 mm
// off along its axis, intrinsics unknown: factors 18-21, the dome centre's
// sd 1.0 mm where the intrinsics given make it 0.07 mm).
constexpr double kTradeOffWarningFactor = 10.0;

// A refined housing a real one would hardly have (Housing::Implausibility):
// a self-calibration that traded the port against the lens, however small
// its standard deviations (issue 21: a flat port 361 mm from the camera
// centre, reported at 0.39 +- 0.07 m).
std::vector<std::string> ImplausibleHousingWarnings(
    const std::map<camera_t, HousedCamera>& cameras) {
  std::vector<std::string> warnings;
  for (const auto& [id, camera] : cameras) {
    if (!camera.housing) continue;
    if (const std::optional<std::string> why = camera.housing->Implausibility()) {
      warnings.push_back(
          "camera " + std::to_string(id) + ": " + *why +
          ": the calibration likely traded the housing against the lens; give the in-air "
          "intrinsics (--ImageReader.camera_params), a closer housing guess, or more views");
    }
  }
  return warnings;
}

std::vector<std::string> SplitParamsInfo(const std::string& info) {
  std::vector<std::string> names;
  std::istringstream in(info);
  for (std::string name; std::getline(in, name, ',');) {
    name.erase(0, name.find_first_not_of(' '));
    names.push_back(name);
  }
  return names;
}

// The strongest correlation of an intrinsic with a housing parameter, per
// camera, as a note when it reaches `limit`. Near +-1 the data tell the two
// apart only through small higher-order effects: a dome decentred along its
// axis magnifies like a longer focal length (own render, dome r 60 mm
// decentred 12 mm along the axis, intrinsics unknown: f 14.5 px and Cz
// 2.3 mm off, each ~1.2 sd; with the in-air intrinsics given Cz 0.05 mm).
// The housing's variance is then at least 1 / (1 - rho^2) times what it
// would be with that intrinsic known.
struct TradeOff {
  std::string text;
  double factor = 1;  // the housing's sd at least this many times that with the intrinsics known
};

std::vector<TradeOff> TradeOffs(const std::map<camera_t, HousedCamera>& cameras,
                                const CalibrationStdDevs& std_devs, double limit) {
  std::vector<TradeOff> trade_offs;
  for (const auto& [id, correlation] : std_devs.intrinsics_housing_correlation) {
    if (correlation.size() == 0) continue;
    Eigen::Index i, j;
    const double strongest = correlation.cwiseAbs().maxCoeff(&i, &j);
    if (!(strongest >= limit)) continue;
    const HousedCamera& camera = cameras.at(id);
    const std::vector<std::string> intrinsic = SplitParamsInfo(camera.camera.ParamsInfo());
    const std::vector<std::string> housing = SplitParamsInfo(camera.housing->ParamsInfo());
    const double factor = 1.0 / std::sqrt(std::max(1e-12, 1.0 - strongest * strongest));
    std::ostringstream note;
    note << std::fixed << std::setprecision(4)
         << (cameras.size() > 1 ? "camera " + std::to_string(id) + ": " : "")
         << intrinsic.at(static_cast<size_t>(i)) << " and " << housing.at(static_cast<size_t>(j))
         << " are correlated at " << std::showpos << correlation(i, j) << std::noshowpos
         << ": the views hardly tell them apart (the housing's standard deviation is at least "
         << std::setprecision(1) << factor
         << " times what it would be with the intrinsics known); give in-air intrinsics "
            "(--ImageReader.camera_params) or views with more depth and angle";
    trade_offs.push_back({note.str(), factor});
  }
  return trade_offs;
}

// The model's images and cameras (the housing override applied), with what
// the source adds (marker detections, position priors, keypoint scales).
SfmInputs InputsOf(const ModelRefinementOptions& options, const SparseModel& model,
                   const ModelSource& source) {
  SfmInputs inputs = SfmInputs::FromSparseModel(model);
  if (options.housing) ReplaceHousings(*options.housing, &inputs.cameras);
  if (options.ba.refine_housing) {
    bool any = false;
    for (const auto& [id, camera] : inputs.cameras) any |= camera.housing.has_value();
    if (!any) {
      throw InputError(
          source.model_name +
          ": no camera has a housing (housings.txt) to refine; give "
          "--Housing.model and --Housing.params or --BundleAdjustment.refine_housing 0");
    }
  }
  if (source.add_extras) {
    for (auto& [id, image] : inputs.images) source.add_extras(&image);
  }
  return inputs;
}

// The metric scale: the model aligned to the images' position priors, or
// the markers' corners triangulated, as the options ask.
void PrepareScale(const ModelRefinementOptions& options, const ModelSource& source, bool use_priors,
                  Reconstruction* r, std::vector<MarkerCorner>* markers,
                  ModelRefinementSummary* result) {
  if (use_priors) {
    const auto alignment = AlignToPositionPriors(r, 5 * options.ba.position_prior_sigma_m);
    if (!alignment) {
      throw InputError(
          source.database_name + ": fewer than 3 registered images of " + source.model_name +
          " have position priors, or their positions are collinear; the scale cannot come "
          "from --PosePrior.position_sigma (run pose_prior_importer, or set it to 0)");
    }
    result->num_position_priors = alignment->num_inliers;
    LOG(INFO) << "refractive_bundle_adjuster: aligned to " << alignment->num_inliers << " of "
              << alignment->num_priors << " position priors (scale "
              << alignment->new_from_old.scale << ", RMS " << alignment->rms_m << " m; "
              << alignment->num_unprojectable_deleted
              << " observations no longer projectable deleted)";
  }
  if (options.marker_scale.side_length_m > 0) {
    *markers = TriangulateMarkerCorners(*r, 4 * options.max_reproj_error_px);
    result->num_marker_corners = static_cast<int>(markers->size());
    if (markers->empty()) {
      throw InputError(
          source.database_name +
          ": no marker corner is seen by two registered images; the "
          "scale cannot come from --Markers.side_length (run feature_masker, or set it to 0)");
    }
    LOG(INFO) << "refractive_bundle_adjuster: " << markers->size()
              << " marker corners give the scale";
  }
}

// The report of camera `camera_id`: parameters, standard deviations,
// exact reprojection RMS overall and per view.
void FillReport(const ModelRefinementOptions& options, const Reconstruction& r, camera_t camera_id,
                const CalibrationStdDevs& std_devs, bool use_priors, CalibrationReport* out) {
  CalibrationReport& report = *out;
  const HousedCamera& camera = r.cameras().at(camera_id);
  report.camera = camera.camera;
  report.housing = camera.housing;
  report.parameters_std_dev = std_devs.intrinsics.count(camera_id)
                                  ? std_devs.intrinsics.at(camera_id)
                                  : std::vector<double>(camera.camera.params.size(), 0.0);
  if (camera.housing) {
    report.housing_std_dev = std_devs.housing.count(camera_id)
                                 ? std_devs.housing.at(camera_id)
                                 : std::vector<double>(camera.housing->params.size(), 0.0);
  }
  const auto of_camera = [camera_id](const std::map<camera_t, std::vector<double>>& std_dev) {
    return std_dev.count(camera_id) ? std_dev.at(camera_id) : std::vector<double>{};
  };
  report.parameters_std_dev_by_noise = of_camera(std_devs.intrinsics_by_noise);
  report.parameters_std_dev_by_clusters = of_camera(std_devs.intrinsics_by_clusters);
  report.housing_std_dev_by_noise = of_camera(std_devs.housing_by_noise);
  report.housing_std_dev_by_clusters = of_camera(std_devs.housing_by_clusters);
  // A refined parameter without a finite standard deviation is
  // undetermined (negative in the report), not held (0).
  for (auto* std_dev : {&report.parameters_std_dev, &report.housing_std_dev,
                        &report.parameters_std_dev_by_noise, &report.parameters_std_dev_by_clusters,
                        &report.housing_std_dev_by_noise, &report.housing_std_dev_by_clusters}) {
    for (double& v : *std_dev) {
      if (!std::isfinite(v)) v = -1.0;
    }
  }
  report.residual_sigma_px = std_devs.sigma0;
  report.pose_frame = "world";  // the reconstruction's frame: there is no target
  report.target_description =
      options.marker_scale.side_length_m > 0
          ? "auto-calibration (SIFT points, ArUco markers of side " +
                std::to_string(options.marker_scale.side_length_m) + " m give the scale)"
      : use_priors ? "self-calibration (SIFT points; position priors of sigma " +
                         std::to_string(options.ba.position_prior_sigma_m) + " m give the scale)"
                   : "auto-calibration (SIFT points; no metric scale)";
  double sum_sq = 0;
  int64_t count = 0;
  std::map<image_t, std::pair<double, int>> per_image;
  for (const auto& [id, point] : r.points()) {
    for (const TrackElement& e : point.track) {
      const double err = r.ReprojectionError(e.image_id, e.point2D_idx, point.xyz);
      if (!std::isfinite(err)) continue;
      sum_sq += err * err;
      ++count;
      per_image[e.image_id].first += err * err;
      per_image[e.image_id].second += 1;
    }
  }
  report.overall_rms_px = count ? std::sqrt(sum_sq / count) : 0.0;
  report.num_points = static_cast<int>(count);
  for (const auto& [image_id, pose] : r.poses()) {
    if (r.inputs().images.at(image_id).camera_id != camera_id) continue;
    CalibratedView view;
    view.image_name = r.inputs().images.at(image_id).name;
    view.cam_from_target = pose;
    const auto it = per_image.find(image_id);
    view.num_points = it == per_image.end() ? 0 : it->second.second;
    view.rms_px = view.num_points ? std::sqrt(it->second.first / view.num_points) : 0.0;
    report.views.push_back(view);
  }
}

// What the adjusted model cannot claim: a housing at a bound, an
// implausible housing, intrinsics traded against the housing (warnings or,
// below the warning factor, notes).
void AddCalibrationWarnings(const ModelRefinementOptions& options, const Reconstruction& r,
                            camera_t at_bound, const CalibrationStdDevs& std_devs,
                            std::vector<std::string>* warnings, std::vector<std::string>* notes,
                            ModelRefinementSummary* result) {
  if (at_bound != kInvalidCameraId) {
    // Not an estimate: its standard deviations describe a bound.
    const Housing& housing = *r.cameras().at(at_bound).housing;
    warnings->push_back(
        "camera " + std::to_string(at_bound) +
        ": the housing ended at a bound of the adjustment (" +
        housing.Refinement().bound_description +
        "), not an estimate; the data traded it against the intrinsics: give the intrinsics, more "
        "views or a closer housing guess");
    LOG(WARNING) << "refractive_bundle_adjuster: " << warnings->back();
  }
  if (options.ba.refine_housing) {
    for (const std::string& warning : ImplausibleHousingWarnings(r.cameras())) {
      warnings->push_back(warning);
      LOG(WARNING) << "refractive_bundle_adjuster: " << warning;
    }
  }
  for (const TradeOff& trade_off : TradeOffs(r.cameras(), std_devs, kTradeOffCorrelation)) {
    if (trade_off.factor >= kTradeOffWarningFactor) {
      warnings->push_back(trade_off.text);
      ++result->num_geometry_warnings;
    } else {
      notes->push_back(trade_off.text);
    }
    LOG(WARNING) << "refractive_bundle_adjuster: " << trade_off.text;
  }
}

// The source's model over `inputs` (filled from it and the source), aligned
// to its scale source. A second attempt loads it again rather than the
// run keeping a copy: a survey's model is a tenth of the refinement's
// memory.
Reconstruction LoadAlignedModel(const ModelRefinementOptions& options, const ModelSource& source,
                                bool use_priors, SfmInputs* inputs,
                                std::vector<MarkerCorner>* markers,
                                ModelRefinementSummary* result) {
  const SparseModel model = source.load_model();
  model.Validate(source.model_name);
  if (model.images.size() < 2) {
    throw InputError(source.model_name + ": " + std::to_string(model.images.size()) +
                     " registered image(s); bundle adjustment needs at least 2");
  }
  if (model.points3D.empty()) {
    // Nothing to adjust: the output would be the input, logged as refined.
    throw InputError(source.model_name +
                     ": no 3D point; bundle adjustment needs the points the images observe");
  }
  *inputs = InputsOf(options, model, source);
  Reconstruction r = Reconstruction::FromSparseModel(inputs, model);
  PrepareScale(options, source, use_priors, &r, markers, result);
  return r;
}

}  // namespace

void AddExtrasOf(const SfmImage& read, SfmImage* image) {
  image->markers = read.markers;
  image->position_prior = read.position_prior;
  if (read.keypoints.size() != image->keypoints.size() ||
      read.scales.size() != read.keypoints.size()) {
    return;
  }
  for (size_t k = 0; k < read.keypoints.size(); ++k) {
    if (!((read.keypoints[k] - image->keypoints[k]).cwiseAbs().maxCoeff() < 1e-3)) return;
  }
  image->scales = read.scales;
}

RefinedModel RefineModel(const ModelRefinementOptions& options, const ModelSource& source) {
  RefinedModel refined;
  ModelRefinementSummary& result = refined.summary;
  const bool use_priors = options.ba.position_prior_sigma_m > 0;
  SfmInputs inputs;
  std::vector<MarkerCorner> markers;
  Reconstruction r = LoadAlignedModel(options, source, use_priors, &inputs, &markers, &result);
  if (options.ba.refine_housing && options.marker_scale.side_length_m <= 0 && !use_priors) {
    LOG(WARNING)
        << "refractive_bundle_adjuster: no marker scale (--Markers.side_length): the model's scale "
           "is arbitrary, so a flat port's distance and a dome's decentering are not in metres "
           "(refraction observes the scale only weakly)";
  }
  SelfCalibration adjustment(options, source.model_name, &r, &markers);
  // The model's own housing at a bound (the mapper can slide a flat port's
  // distance into its floor under a focal length that is too long): from
  // there the solve stays there, even with the intrinsics adjusted first.
  // It starts from the guess's bound parameters instead, the intrinsics
  // first (figures: docs/dev/auto_calibration_notes.md).
  const bool start_at_bound = adjustment.joint() &&
                              adjustment.HousingAtBound() != kInvalidCameraId &&
                              options.housing_guess.has_value();
  if (start_at_bound) MoveHousingsOffBound(options.housing_guess, &r);
  CalibrationStdDevs std_devs;
  SelfCalibrationOutcome outcome = adjustment.Calibrate(start_at_bound, &std_devs);
  if (adjustment.joint() && !start_at_bound && adjustment.HousingAtBound() != kInvalidCameraId) {
    // The housing slid into a bound under the mapper's intrinsics: adjusting
    // the intrinsics first (housing held) moves them to the right side of
    // the trade (docs/dev/auto_calibration_notes.md).
    LOG(WARNING) << "refractive_bundle_adjuster: the housing ended at a bound; adjusting again, "
                    "the intrinsics "
                    "first";
    markers.clear();
    r = LoadAlignedModel(options, source, use_priors, &inputs, &markers, &result);
    std_devs = CalibrationStdDevs();
    outcome = adjustment.Calibrate(true, &std_devs);
  }
  result.num_filtered = outcome.num_filtered;
  result.principal_point_held = outcome.principal_point_held;
  std::vector<std::string> notes = std::move(outcome.notes);
  std::vector<std::string> warnings = std::move(outcome.warnings);
  AddCalibrationWarnings(options, r, adjustment.HousingAtBound(), std_devs, &warnings, &notes,
                         &result);
  const camera_t camera_id = r.cameras().begin()->first;
  if (r.cameras().size() > 1) {
    LOG(WARNING) << "refractive_bundle_adjuster: " << r.cameras().size()
                 << " cameras; the report describes camera " << camera_id << " (the model has all)";
  }
  CalibrationReport& report = result.report;
  FillReport(options, r, camera_id, std_devs, use_priors, &report);
  report.notes = std::move(notes);
  report.warnings = std::move(warnings);
  refined.model = r.ToSparseModel();
  report.verdict = JudgeCalibration(report, refined.model, camera_id);
  return refined;
}

}  // namespace portcal
