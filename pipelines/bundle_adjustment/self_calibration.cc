#include "pipelines/bundle_adjustment/self_calibration.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

void SelfCalibrationOptions::Check() const {
  marker_scale.Check();
  if (!(max_reproj_error_px > 0)) {
    throw OptionError("--BundleAdjustment.max_reproj_error", max_reproj_error_px, "> 0 px");
  }
  if (!(robust_function_tolerance > 0 && robust_function_tolerance < 1)) {
    throw OptionError("--BundleAdjustment.robust_function_tolerance", robust_function_tolerance,
                      "in (0, 1)");
  }
  if (!(principal_point_test_sigmas >= 0)) {
    throw OptionError("--BundleAdjustment.principal_point_test_sigmas", principal_point_test_sigmas,
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

std::string FormatSigmas(double sigmas) {
  std::ostringstream out;
  out << sigmas << " sigma";
  return out.str();
}

// Whether any camera's refined principal point lies more than `sigmas`
// standard deviations (per axis) from the image centre; describes each
// camera's offset in `offset`.
bool PrincipalPointOffCentre(const std::map<camera_t, HousedCamera>& cameras,
                             const CalibrationStdDevs& std_devs, double sigmas,
                             std::ostringstream* offset) {
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
      *offset << (k ? ", " : "") << axis[k] << " " << std::showpos << delta << std::noshowpos
              << " px (sd " << sigma << ")";
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
double PoorPrincipalPointStdDev(const std::map<camera_t, HousedCamera>& cameras,
                                const CalibrationStdDevs& std_devs) {
  double worst = 0;
  for (const auto& [id, camera] : cameras) {
    const auto sd = std_devs.intrinsics.find(id);
    if (sd == std_devs.intrinsics.end()) continue;
    const double bound =
        kMaxPrincipalPointStdDevFraction * std::max(camera.camera.width, camera.camera.height);
    for (int idx : CameraModelPrincipalPointIdxs(camera.camera.model_id)) {
      const double sigma = sd->second[idx];
      if (!(sigma <= bound)) worst = std::max(worst, std::isfinite(sigma) ? sigma : HUGE_VAL);
    }
  }
  return worst;
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

}  // namespace

SelfCalibration::SelfCalibration(const SelfCalibrationOptions& options, std::string model_name,
                                 Reconstruction* r, std::vector<MarkerCorner>* markers)
    : options_(options),
      model_name_(std::move(model_name)),
      r_(*r),
      markers_(*markers),
      cameras_before_(r->cameras()),
      joint_(options.ba.refine_housing &&
             (options.ba.refine_focal_length || options.ba.refine_principal_point ||
              options.ba.refine_extra_params)) {}

camera_t SelfCalibration::HousingAtBound() const {
  return options_.ba.refine_housing ? CameraWithHousingAtBound(r_.cameras()) : kInvalidCameraId;
}

SelfCalibrationOutcome SelfCalibration::Calibrate(bool intrinsics_first,
                                                  CalibrationStdDevs* std_devs) {
  SelfCalibrationOutcome outcome;
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
  Solve(options_.ba, std_devs, &outcome);
  if (options_.ba.refine_principal_point) WarnIfPrincipalPointPoor(*std_devs, &outcome);
  if (options_.ba.refine_principal_point && options_.principal_point_test_sigmas > 0) {
    outcome.notes.push_back(TestPrincipalPoint(std_devs, &outcome));
    LOG(INFO) << "refractive_bundle_adjuster: " << outcome.notes.back();
  }
  return outcome;
}

// `ba` for a solve that decides the inliers: with held weights, robust to
// the robust tolerance.
BundleAdjustmentOptions SelfCalibration::Robust(const BundleAdjustmentOptions& ba) const {
  BundleAdjustmentOptions robust = ba;
  if (options_.hold_weights) {
    robust.function_tolerance = options_.robust_function_tolerance;
    robust.max_unsettled_weight_fraction = options_.robust_max_unsettled_weights;
  }
  return robust;
}

// A first solve, outliers out, then the final solve (the weights held, as
// the options say) with covariance.
void SelfCalibration::Solve(const BundleAdjustmentOptions& ba, CalibrationStdDevs* std_devs,
                            SelfCalibrationOutcome* outcome) {
  AdjustBundle(&r_, Robust(ba), BundleAdjustmentScope(), &markers_, options_.marker_scale);
  for (const auto& [id, camera] : r_.cameras()) {
    // Garbage must not pass for a calibration.
    std::string why;
    if (ImplausibleIntrinsics(cameras_before_.at(id).camera, camera.camera, &why)) {
      throw NumericalError(model_name_ + ": refining camera " + std::to_string(id) +
                           " gave implausible intrinsics (" + why +
                           "): the reconstruction is likely "
                           "wrong (mean reprojection error " +
                           std::to_string(r_.MeanReprojectionError()) +
                           " px); give the intrinsics (--ImageReader.camera_params) or more views");
    }
  }
  outcome->num_filtered += r_.DeleteObservationsBeyond(options_.max_reproj_error_px);
  const BundleAdjustmentOptions final_solve =
      options_.hold_weights ? ba.WithWeightsHeld(options_.held_trust_region_radius) : ba;
  AdjustBundle(&r_, final_solve, BundleAdjustmentScope(), &markers_, options_.marker_scale,
               std_devs);
}

void SelfCalibration::WarnIfPrincipalPointPoor(const CalibrationStdDevs& std_devs,
                                               SelfCalibrationOutcome* outcome) const {
  const double sigma = PoorPrincipalPointStdDev(r_.cameras(), std_devs);
  if (!(sigma > 0)) return;
  std::ostringstream text;
  text << "the principal point is poorly determined (std dev " << std::setprecision(3) << sigma
       << " px): the focal length, distortion and housing may have taken up its offset; give the "
          "in-air "
          "intrinsics (--ImageReader.camera_params), more views, or views nearer the image corners";
  outcome->warnings.push_back(text.str());
  LOG(WARNING) << "refractive_bundle_adjuster: " << outcome->warnings.back();
}

// Holds the principal point at the image centre again (and solves) unless
// it lies beyond the test's sigmas from it; returns the note.
std::string SelfCalibration::TestPrincipalPoint(CalibrationStdDevs* std_devs,
                                                SelfCalibrationOutcome* outcome) {
  std::ostringstream offset;
  if (PrincipalPointOffCentre(r_.cameras(), *std_devs, options_.principal_point_test_sigmas,
                              &offset)) {
    outcome->principal_point_held = false;
    return "principal point refined: off the image centre by " + offset.str();
  }
  CentrePrincipalPoints(&r_);
  BundleAdjustmentOptions held = options_.ba;
  held.refine_principal_point = false;
  *std_devs = CalibrationStdDevs();
  Solve(held, std_devs, outcome);
  outcome->principal_point_held = true;
  return "principal point held at the image centre: refined, it was off by " + offset.str() +
         ", within " + FormatSigmas(options_.principal_point_test_sigmas);
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
    LOG(INFO) << "refractive_bundle_adjuster: camera " << id
              << ": housing started again off its bound, from the "
              << "guess's " << refinement.position_name;
  }
  r->UpdateRays();
}

}  // namespace portcal
