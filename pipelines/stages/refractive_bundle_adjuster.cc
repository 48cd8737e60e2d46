#include "pipelines/stages/refractive_bundle_adjuster.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "pipelines/bundle_adjustment/position_priors.h"
#include "pipelines/report/calibration_html.h"

namespace fs = std::filesystem;

namespace portcal {

void RefractiveBundleAdjusterOptions::Check() const {
  if (input_path.empty()) throw OptionError("--input_path", "''", "a sparse model directory");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a directory for the results");
  CheckOutputFolder("--output_path", output_path);
  if (marker_scale.side_length_m > 0 && database_path.empty()) {
    throw OptionError("--database_path", "''", "the database with the marker detections (--Markers.side_length)");
  }
  if (marker_scale.side_length_m < 0) {
    throw OptionError("--Markers.side_length", std::to_string(marker_scale.side_length_m), ">= 0 m");
  }
  if (!(marker_scale.sigma_m > 0)) {
    throw OptionError("--Markers.side_sigma", std::to_string(marker_scale.sigma_m), "> 0 m");
  }
  if (ba.position_prior_sigma_m > 0 && database_path.empty()) {
    throw OptionError("--database_path", "''", "the database with the position priors (--PosePrior.position_sigma)");
  }
  if (!(max_reproj_error_px > 0)) {
    throw OptionError("--BundleAdjustment.max_reproj_error", std::to_string(max_reproj_error_px), "> 0 px");
  }
  if (!(robust_function_tolerance > 0 && robust_function_tolerance < 1)) {
    throw OptionError("--BundleAdjustment.robust_function_tolerance", std::to_string(robust_function_tolerance),
                      "in (0, 1)");
  }
  if (!(principal_point_test_sigmas >= 0)) {
    throw OptionError("--BundleAdjustment.principal_point_test_sigmas", std::to_string(principal_point_test_sigmas),
                      ">= 0 (0: no test)");
  }
  // ba as the robust and the held solves take it (their two options are
  // checked where BundleAdjustmentOptions checks its own).
  BundleAdjustmentOptions staged = ba;
  staged.max_unsettled_weight_fraction = robust_max_unsettled_weights;
  staged.initial_trust_region_radius = held_trust_region_radius;
  staged.Check();
}

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

std::string FormatSigmas(double sigmas) {
  std::ostringstream out;
  out << sigmas << " sigma";
  return out.str();
}

// Whether any camera's refined principal point lies more than `sigmas`
// standard deviations (per axis) from the image centre; describes each
// camera's offset in `offset`.
bool PrincipalPointOffCentre(const std::map<camera_t, HousedCamera>& cameras, const CalibrationStdDevs& std_devs,
                             double sigmas, std::ostringstream* offset) {
  bool significant = false;
  *offset << std::fixed << std::setprecision(2);
  for (const auto& [id, camera] : cameras) {
    const std::vector<int> idxs = CameraModelPrincipalPointIdxs(camera.camera.model_id);
    const auto sd = std_devs.intrinsics.find(id);
    if (idxs.size() != 2 || sd == std_devs.intrinsics.end()) continue;
    const double centre[2] = {camera.camera.width / 2.0, camera.camera.height / 2.0};
    const char* axis = "xy";
    if (offset->tellp() > 0) *offset << "; ";
    if (cameras.size() > 1) *offset << "camera " << id << ": ";
    for (size_t k = 0; k < 2; ++k) {
      const double delta = camera.camera.params[idxs[k]] - centre[k];
      const double sigma = sd->second[idxs[k]];
      // No finite standard deviation: the data cannot tell, so not significant.
      const bool beyond = sigma > 0 && std::isfinite(sigma) && std::abs(delta) > sigmas * sigma;
      significant |= beyond;
      *offset << (k ? ", " : "") << axis[k] << " " << std::showpos << delta << std::noshowpos << " px (sd "
              << sigma << ")";
    }
  }
  return significant;
}

// A principal point whose standard deviation exceeds this fraction of the
// image's larger side is not determined: held at the centre or not, the
// focal length, distortion and housing took up what it could not say (own
// render, 960 x 540, wide lens 10 px off the centre: held with sd 2.7 /
// 5.0 px, f came out 11 px off at 7.7 sigma; well-determined sets: sd
// 0.1-1.2 px).
constexpr double kMaxPrincipalPointStdDevFraction = 0.002;

// The largest principal point standard deviation above that bound, or 0.
double PoorPrincipalPointStdDev(const std::map<camera_t, HousedCamera>& cameras, const CalibrationStdDevs& std_devs) {
  double worst = 0;
  for (const auto& [id, camera] : cameras) {
    const auto sd = std_devs.intrinsics.find(id);
    if (sd == std_devs.intrinsics.end()) continue;
    const double bound = kMaxPrincipalPointStdDevFraction * std::max(camera.camera.width, camera.camera.height);
    for (int idx : CameraModelPrincipalPointIdxs(camera.camera.model_id)) {
      const double sigma = sd->second[idx];
      if (!(sigma <= bound)) worst = std::max(worst, std::isfinite(sigma) ? sigma : HUGE_VAL);
    }
  }
  return worst;
}

// A refined housing a real one would hardly have (Housing::Implausibility):
// a self-calibration that traded the port against the lens, however small
// its standard deviations (issue 21: a flat port 361 mm from the camera
// centre, reported at 0.39 +- 0.07 m).
std::vector<std::string> ImplausibleHousingWarnings(const std::map<camera_t, HousedCamera>& cameras) {
  std::vector<std::string> warnings;
  for (const auto& [id, camera] : cameras) {
    if (!camera.housing) continue;
    if (const std::optional<std::string> why = camera.housing->Implausibility()) {
      warnings.push_back("camera " + std::to_string(id) + ": " + *why +
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

std::vector<TradeOff> TradeOffs(const std::map<camera_t, HousedCamera>& cameras, const CalibrationStdDevs& std_devs,
                                double limit) {
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
    note << std::fixed << std::setprecision(4) << (cameras.size() > 1 ? "camera " + std::to_string(id) + ": " : "")
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

// Sets every camera's principal point to its image centre.
void CentrePrincipalPoints(Reconstruction* r) {
  for (auto& [id, camera] : r->mutable_cameras()) {
    const std::vector<int> idxs = CameraModelPrincipalPointIdxs(camera.camera.model_id);
    if (idxs.size() != 2) continue;
    camera.camera.params[idxs[0]] = camera.camera.width / 2.0;
    camera.camera.params[idxs[1]] = camera.camera.height / 2.0;
  }
}

// Moves the position of every housing at a bound of the adjustment (flat:
// distance; dome: centre) to the guess's, when the guess is of the same
// model; the rest stays.
void MoveHousingsOffBound(const std::optional<Housing>& guess, Reconstruction* r) {
  if (!guess) return;
  const Housing& from = *guess;
  for (auto& [id, camera] : r->mutable_cameras()) {
    if (!camera.housing || !camera.housing->AtBound()) continue;
    if (!from.SameModel(*camera.housing)) continue;
    const HousingRefinement refinement = camera.housing->Refinement();
    for (int k : refinement.position) {
      camera.housing->params[static_cast<size_t>(k)] = from.params[static_cast<size_t>(k)];
    }
    LOG(INFO) << "refractive_bundle_adjuster: camera " << id << ": housing started again off its bound, from the "
              << "guess's " << refinement.position_name;
  }
  r->UpdateRays();
}

// The model's images and cameras (the housing override applied), with the
// database's marker detections, position priors and keypoint scales.
SfmInputs ReadAdjusterInputs(const RefractiveBundleAdjusterOptions& options, const SparseModel& model) {
  SfmInputs inputs = SfmInputs::FromSparseModel(model);
  if (options.housing) ReplaceHousings(*options.housing, &inputs.cameras);
  if (options.ba.refine_housing) {
    bool any = false;
    for (const auto& [id, camera] : inputs.cameras) any |= camera.housing.has_value();
    if (!any) {
      throw InputError(options.input_path + ": no camera has a housing (housings.txt) to refine; give "
                       "--Housing.model and --Housing.params or --BundleAdjustment.refine_housing 0");
    }
  }
  if (!options.database_path.empty()) {
    Database database(options.database_path, Database::OpenMode::kReadOnly);
    for (auto& [id, image] : inputs.images) {
      const auto row = database.ReadImageWithName(image.name);
      if (!row) continue;
      image.markers = database.ReadMarkerDetections(row->image_id);
      image.position_prior = row->PriorPosition();
      // The keypoints' scales, for weighting, when the model's points are
      // the database's keypoints.
      const FeatureKeypoints keypoints = database.ReadKeypoints(row->image_id);
      if (keypoints.size() != image.keypoints.size()) continue;
      bool same = true;
      for (size_t k = 0; k < keypoints.size() && same; ++k) {
        same = std::abs(keypoints[k].x - image.keypoints[k].x()) < 1e-3 &&
               std::abs(keypoints[k].y - image.keypoints[k].y()) < 1e-3;
      }
      if (!same) continue;
      for (const FeatureKeypoint& k : keypoints) image.scales.push_back(k.ComputeScale());
    }
  }
  return inputs;
}

// The metric scale: the model aligned to the images' position priors, or
// the markers' corners triangulated, as the options ask.
void PrepareScale(const RefractiveBundleAdjusterOptions& options, bool use_priors, Reconstruction* r,
                  std::vector<MarkerCorner>* markers, RefractiveBundleAdjusterSummary* result) {
  if (use_priors) {
    const auto alignment = AlignToPositionPriors(r, 5 * options.ba.position_prior_sigma_m);
    if (!alignment) {
      throw InputError(options.database_path + ": fewer than 3 registered images of " + options.input_path +
                       " have position priors, or their positions are collinear; the scale cannot come "
                       "from --PosePrior.position_sigma (run pose_prior_importer, or set it to 0)");
    }
    result->num_position_priors = alignment->num_inliers;
    LOG(INFO) << "refractive_bundle_adjuster: aligned to " << alignment->num_inliers << " of "
              << alignment->num_priors << " position priors (scale " << alignment->new_from_old.scale
              << ", RMS " << alignment->rms_m << " m; " << alignment->num_unprojectable_deleted
              << " observations no longer projectable deleted)";
  }
  if (options.marker_scale.side_length_m > 0) {
    *markers = TriangulateMarkerCorners(*r, 4 * options.max_reproj_error_px);
    result->num_marker_corners = static_cast<int>(markers->size());
    if (markers->empty()) {
      throw InputError(options.database_path + ": no marker corner is seen by two registered images; the "
                       "scale cannot come from --Markers.side_length (run feature_masker, or set it to 0)");
    }
    LOG(INFO) << "refractive_bundle_adjuster: " << markers->size() << " marker corners give the scale";
  }
}

// The report of camera `camera_id`: parameters, standard deviations,
// exact reprojection RMS overall and per view.
void FillReport(const RefractiveBundleAdjusterOptions& options, const Reconstruction& r, camera_t camera_id,
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
  for (auto* std_dev : {&report.parameters_std_dev, &report.housing_std_dev, &report.parameters_std_dev_by_noise,
                        &report.parameters_std_dev_by_clusters, &report.housing_std_dev_by_noise,
                        &report.housing_std_dev_by_clusters}) {
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

// The adjustment of one model, in stages: with the intrinsics refined too,
// the housing is first adjusted under the mapper's intrinsics (started
// jointly from an untilted guess, the focal length and the port distance
// trade off and the solve can slide into the distance's lower bound with a
// wrong focal length; docs/dev/auto_calibration_notes.md); each solve twice, outliers
// dropped in between; then the principal point test.
class StagedAdjustment {
 public:
  StagedAdjustment(const RefractiveBundleAdjusterOptions& options, Reconstruction* r,
                   std::vector<MarkerCorner>* markers, RefractiveBundleAdjusterSummary* result)
      : options_(options),
        r_(*r),
        markers_(*markers),
        result_(*result),
        cameras_before_(r->cameras()),
        joint_(options.ba.refine_housing &&
               (options.ba.refine_focal_length || options.ba.refine_principal_point || options.ba.refine_extra_params)) {}

  bool joint() const { return joint_; }
  // The camera whose housing sits at a bound of the adjustment, if any.
  camera_t HousingAtBound() const {
    return options_.ba.refine_housing ? CameraWithHousingAtBound(r_.cameras()) : kInvalidCameraId;
  }
  const std::vector<std::string>& warnings() const { return warnings_; }

  // The staged adjustment, the principal point test; returns the report's
  // notes (warnings() has the warnings).
  std::vector<std::string> Calibrate(bool intrinsics_first, CalibrationStdDevs* std_devs) {
    std::vector<std::string> notes;
    warnings_.clear();
    // The staged solves only start the next: robust, to the robust tolerance.
    if (joint_ && intrinsics_first) {
      BundleAdjustmentOptions intrinsics = Robust(options_.ba);
      intrinsics.refine_housing = false;
      AdjustBundle(&r_, intrinsics, BundleAdjustmentScope(), &markers_, options_.marker_scale);
    }
    if (joint_) {
      AdjustBundle(&r_, Robust(options_.ba).WithIntrinsicsHeld(), BundleAdjustmentScope(), &markers_,
                   options_.marker_scale);
    }
    Solve(options_.ba, std_devs);
    if (options_.ba.refine_principal_point) WarnIfPrincipalPointPoor(*std_devs);
    if (options_.ba.refine_principal_point && options_.principal_point_test_sigmas > 0) {
      notes.push_back(TestPrincipalPoint(std_devs));
      LOG(INFO) << "refractive_bundle_adjuster: " << notes.back();
    }
    return notes;
  }

 private:
  // `ba` for a solve that decides the inliers: with held weights, robust to
  // the robust tolerance.
  BundleAdjustmentOptions Robust(const BundleAdjustmentOptions& ba) const {
    BundleAdjustmentOptions robust = ba;
    if (options_.hold_weights) {
      robust.function_tolerance = options_.robust_function_tolerance;
      robust.max_unsettled_weight_fraction = options_.robust_max_unsettled_weights;
    }
    return robust;
  }

  // A first solve, outliers out, then the final solve (the weights held, as
  // the options say) with covariance.
  void Solve(const BundleAdjustmentOptions& ba, CalibrationStdDevs* std_devs) {
    AdjustBundle(&r_, Robust(ba), BundleAdjustmentScope(), &markers_, options_.marker_scale);
    for (const auto& [id, camera] : r_.cameras()) {
      // Garbage must not pass for a calibration.
      std::string why;
      if (ImplausibleIntrinsics(cameras_before_.at(id).camera, camera.camera, &why)) {
        throw NumericalError(options_.input_path + ": refining camera " + std::to_string(id) +
                             " gave implausible intrinsics (" + why + "): the reconstruction is likely "
                             "wrong (mean reprojection error " + std::to_string(r_.MeanReprojectionError()) +
                             " px); give the intrinsics (--ImageReader.camera_params) or more views");
      }
    }
    result_.num_filtered += r_.DeleteObservationsBeyond(options_.max_reproj_error_px);
    const BundleAdjustmentOptions final_solve =
        options_.hold_weights ? ba.WithWeightsHeld(options_.held_trust_region_radius) : ba;
    AdjustBundle(&r_, final_solve, BundleAdjustmentScope(), &markers_, options_.marker_scale, std_devs);
  }

  void WarnIfPrincipalPointPoor(const CalibrationStdDevs& std_devs) {
    const double sigma = PoorPrincipalPointStdDev(r_.cameras(), std_devs);
    if (!(sigma > 0)) return;
    std::ostringstream text;
    text << "the principal point is poorly determined (std dev " << std::setprecision(3) << sigma
         << " px): the focal length, distortion and housing may have taken up its offset; give the in-air "
            "intrinsics (--ImageReader.camera_params), more views, or views nearer the image corners";
    warnings_.push_back(text.str());
    LOG(WARNING) << "refractive_bundle_adjuster: " << warnings_.back();
  }

  // Holds the principal point at the image centre again (and solves) unless
  // it lies beyond the test's sigmas from it; returns the note.
  std::string TestPrincipalPoint(CalibrationStdDevs* std_devs) {
    std::ostringstream offset;
    if (PrincipalPointOffCentre(r_.cameras(), *std_devs, options_.principal_point_test_sigmas, &offset)) {
      result_.principal_point_held = false;
      return "principal point refined: off the image centre by " + offset.str();
    }
    CentrePrincipalPoints(&r_);
    BundleAdjustmentOptions held = options_.ba;
    held.refine_principal_point = false;
    *std_devs = CalibrationStdDevs();
    Solve(held, std_devs);
    result_.principal_point_held = true;
    return "principal point held at the image centre: refined, it was off by " + offset.str() + ", within " +
           FormatSigmas(options_.principal_point_test_sigmas);
  }

  const RefractiveBundleAdjusterOptions& options_;
  Reconstruction& r_;
  std::vector<MarkerCorner>& markers_;
  RefractiveBundleAdjusterSummary& result_;
  const std::map<camera_t, HousedCamera> cameras_before_;
  const bool joint_;
  std::vector<std::string> warnings_;
};

// What the adjusted model cannot claim: a housing at a bound, an
// implausible housing, intrinsics traded against the housing (warnings or,
// below the warning factor, notes).
void AddCalibrationWarnings(const RefractiveBundleAdjusterOptions& options, const Reconstruction& r,
                            camera_t at_bound, const CalibrationStdDevs& std_devs, std::vector<std::string>* warnings,
                            std::vector<std::string>* notes, RefractiveBundleAdjusterSummary* result) {
  if (at_bound != kInvalidCameraId) {
    // Not an estimate: its standard deviations describe a bound.
    const Housing& housing = *r.cameras().at(at_bound).housing;
    warnings->push_back("camera " + std::to_string(at_bound) + ": the housing ended at a bound of the adjustment (" +
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

// The adjusted model and the report of its first camera (RMS of the exact
// reprojection error).
void WriteAdjusted(const RefractiveBundleAdjusterOptions& options, const Reconstruction& r,
                   const CalibrationStdDevs& std_devs, bool use_priors, std::vector<std::string> notes,
                   std::vector<std::string> warnings, RefractiveBundleAdjusterSummary* result) {
  const camera_t camera_id = r.cameras().begin()->first;
  if (r.cameras().size() > 1) {
    LOG(WARNING) << "refractive_bundle_adjuster: " << r.cameras().size()
                 << " cameras; the report describes camera " << camera_id << " (the model has all)";
  }
  CalibrationReport& report = result->report;
  FillReport(options, r, camera_id, std_devs, use_priors, &report);
  report.notes = std::move(notes);
  report.warnings = std::move(warnings);
  const SparseModel model = r.ToSparseModel();
  report.verdict = JudgeCalibration(report, model, camera_id);
  WriteSparseModel(model, options.output_path, ModelFormat::kBinary);
  WriteCalibrationReport(report, options.output_path);
  WriteHtml(SelfCalibrationHtml(report, model, "Refractive bundle adjustment"), options.output_path);
  LOG(INFO) << "refractive_bundle_adjuster: RMS " << report.overall_rms_px << " px over " << report.num_points
            << " observations; " << result->num_filtered << " observations dropped; written to "
            << options.output_path;
  const HousedCamera& camera = r.cameras().at(camera_id);
  if (camera.housing) LOG(INFO) << "housing: " << camera.housing->ModelName() << " " << [&] {
    std::string s;
    for (double v : camera.housing->params) s += std::to_string(v) + " ";
    return s;
  }();
}

// The input model over `inputs` (filled from it and the database), aligned
// to its scale source. The run reads it again rather than keeping a copy
// for its rare second attempt: a survey's model is a tenth of the
// refinement's memory.
Reconstruction ReadAlignedModel(const RefractiveBundleAdjusterOptions& options, bool use_priors, SfmInputs* inputs,
                                std::vector<MarkerCorner>* markers, RefractiveBundleAdjusterSummary* result) {
  const SparseModel model = ReadSparseModel(options.input_path);
  model.Validate(options.input_path);
  if (model.images.size() < 2) {
    throw InputError(options.input_path + ": " + std::to_string(model.images.size()) +
                     " registered image(s); bundle adjustment needs at least 2");
  }
  if (model.points3D.empty()) {
    // Nothing to adjust: the output would be the input, logged as refined.
    throw InputError(options.input_path + ": no 3D point; bundle adjustment needs the points the images observe");
  }
  *inputs = ReadAdjusterInputs(options, model);
  Reconstruction r = Reconstruction::FromSparseModel(inputs, model);
  PrepareScale(options, use_priors, &r, markers, result);
  return r;
}

}  // namespace

RefractiveBundleAdjusterSummary RunRefractiveBundleAdjuster(const RefractiveBundleAdjusterOptions& options,
                                                            ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  RefractiveBundleAdjusterSummary result;
  const bool use_priors = options.ba.position_prior_sigma_m > 0;
  SfmInputs inputs;
  std::vector<MarkerCorner> markers;
  Reconstruction r = ReadAlignedModel(options, use_priors, &inputs, &markers, &result);
  if (options.ba.refine_housing && options.marker_scale.side_length_m <= 0 && !use_priors) {
    LOG(WARNING) << "refractive_bundle_adjuster: no marker scale (--Markers.side_length): the model's scale "
                    "is arbitrary, so a flat port's distance and a dome's decentering are not in metres "
                    "(refraction observes the scale only weakly)";
  }
  StagedAdjustment adjustment(options, &r, &markers, &result);
  // The model's own housing at a bound (the mapper can slide a flat port's
  // distance into its floor under a focal length that is too long): from
  // there the solve stays there, even with the intrinsics adjusted first.
  // It starts from the guess's bound parameters instead, the intrinsics
  // first (figures: docs/dev/auto_calibration_notes.md).
  const bool start_at_bound =
      adjustment.joint() && adjustment.HousingAtBound() != kInvalidCameraId && options.housing_guess.has_value();
  if (start_at_bound) MoveHousingsOffBound(options.housing_guess, &r);
  CalibrationStdDevs std_devs;
  std::vector<std::string> notes = adjustment.Calibrate(start_at_bound, &std_devs);
  if (adjustment.joint() && !start_at_bound && adjustment.HousingAtBound() != kInvalidCameraId) {
    // The housing slid into a bound under the mapper's intrinsics: adjusting
    // the intrinsics first (housing held) moves them to the right side of
    // the trade (docs/dev/auto_calibration_notes.md).
    LOG(WARNING) << "refractive_bundle_adjuster: the housing ended at a bound; adjusting again, the intrinsics "
                    "first";
    markers.clear();
    r = ReadAlignedModel(options, use_priors, &inputs, &markers, &result);
    result.num_filtered = 0;
    std_devs = CalibrationStdDevs();
    notes = adjustment.Calibrate(true, &std_devs);
  }
  std::vector<std::string> warnings = adjustment.warnings();
  AddCalibrationWarnings(options, r, adjustment.HousingAtBound(), std_devs, &warnings, &notes, &result);
  WriteAdjusted(options, r, std_devs, use_priors, std::move(notes), std::move(warnings), &result);
  new_output.Keep();
  return result;
}

}  // namespace portcal
