#include "pipelines/bundle_adjustment/bundle_adjustment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace portcal {

void BundleAdjustmentOptions::Check() const {
  if (!(sigma_px > 0)) throw OptionError("--BundleAdjustment.sigma_px", sigma_px, "> 0");
  if (max_num_iterations < 1) {
    throw OptionError("--BundleAdjustment.max_num_iterations", max_num_iterations, ">= 1");
  }
  if (!(loss_scale >= 0)) throw OptionError("--BundleAdjustment.loss_scale", loss_scale, ">= 0");
  if (!(position_prior_sigma_m >= 0)) {
    throw OptionError("--PosePrior.position_sigma", position_prior_sigma_m, ">= 0 m");
  }
  if (!(function_tolerance > 0)) {
    throw OptionError("--BundleAdjustment.function_tolerance", function_tolerance, "> 0");
  }
  if (!(max_unsettled_weight_fraction >= 0 && max_unsettled_weight_fraction < 1)) {
    throw OptionError("--BundleAdjustment.robust_max_unsettled_weights",
                      max_unsettled_weight_fraction, "in [0, 1)");
  }
  if (!(initial_trust_region_radius > 0 && initial_trust_region_radius <= 1e16)) {
    throw OptionError("--BundleAdjustment.held_trust_region_radius", initial_trust_region_radius,
                      "in (0, 1e16]");
  }
}

BundleAdjustmentOptions BundleAdjustmentOptions::WithIntrinsicsHeld() const {
  BundleAdjustmentOptions held = *this;
  held.refine_focal_length = held.refine_principal_point = held.refine_extra_params = false;
  return held;
}

BundleAdjustmentOptions BundleAdjustmentOptions::WithWeightsHeld(
    double first_trust_region_radius) const {
  BundleAdjustmentOptions held = *this;
  held.hold_loss_weights = true;
  held.max_unsettled_weight_fraction = 0;  // the weights no longer move
  held.initial_trust_region_radius = first_trust_region_radius;
  return held;
}

void MarkerScale::Check() const {
  if (!(side_length_m >= 0)) throw OptionError("--Markers.side_length", side_length_m, ">= 0 m");
  if (!(sigma_m > 0)) throw OptionError("--Markers.side_sigma", sigma_m, "> 0 m");
}

bool ImplausibleIntrinsics(const Camera& before, const Camera& after, std::string* why) {
  std::ostringstream text;
  const double ratio = after.MeanFocalLength() / before.MeanFocalLength();
  if (!(ratio > 0.5 && ratio < 2.0)) {
    text << "focal length " << after.MeanFocalLength() << " px from " << before.MeanFocalLength()
         << " px";
  }
  const std::vector<std::string> names = SplitTokens(after.ParamsInfo(), ", ");
  for (int idx : CameraModelExtraParamsIdxs(after.model_id)) {
    if (!(std::abs(after.params[idx]) < 1.0)) {
      text << (text.tellp() > 0 ? ", " : "") << names.at(idx) << " = " << after.params[idx];
    }
  }
  if (why) *why = text.str();
  return text.tellp() > 0;
}

std::vector<MarkerCorner> TriangulateMarkerCorners(const Reconstruction& reconstruction,
                                                   double max_error_px) {
  std::map<std::pair<int, int>, MarkerCorner> corners;
  for (const auto& [image_id, pose] : reconstruction.poses()) {
    for (const MarkerDetection& m : reconstruction.inputs().images.at(image_id).markers) {
      for (int c = 0; c < 4; ++c) {
        MarkerCorner& corner = corners[{m.marker_id, c}];
        corner.marker_id = m.marker_id;
        corner.corner = c;
        corner.observations.emplace_back(image_id, m.corners[c]);
      }
    }
  }
  std::vector<MarkerCorner> result;
  for (auto& [key, corner] : corners) {
    if (corner.observations.size() < 2) continue;
    std::vector<Ray3d> rays;
    for (const auto& [image_id, pixel] : corner.observations) {
      const HousedCamera& camera = reconstruction.CameraOf(image_id);
      const auto ray = camera.Unproject(pixel);
      if (ray) rays.push_back(RayInWorld(*ray, reconstruction.poses().at(image_id)));
    }
    const auto xyz = TriangulateRays(rays);
    if (!xyz) continue;
    // Drop observations that disagree (a marker id seen twice, a bad corner).
    std::vector<std::pair<image_t, Eigen::Vector2d>> kept;
    for (const auto& [image_id, pixel] : corner.observations) {
      const HousedCamera& camera = reconstruction.CameraOf(image_id);
      const auto projected = camera.Project(reconstruction.poses().at(image_id) * *xyz);
      if (projected && (*projected - pixel).norm() < max_error_px)
        kept.emplace_back(image_id, pixel);
    }
    if (kept.size() < 2) continue;
    corner.observations = kept;
    corner.xyz = *xyz;
    result.push_back(corner);
  }
  return result;
}

std::optional<double> MarkerScaleRatio(const std::vector<MarkerCorner>& corners,
                                       double side_length_m, bool with_diagonals) {
  std::map<int, std::map<int, Eigen::Vector3d>> corners_of;
  for (const MarkerCorner& corner : corners)
    corners_of[corner.marker_id][corner.corner] = corner.xyz;
  std::vector<double> ratios;
  for (const auto& [id, placed] : corners_of) {
    for (auto a = placed.begin(); a != placed.end(); ++a) {
      for (auto b = std::next(a); b != placed.end(); ++b) {
        const bool diagonal = b->first - a->first == 2;
        if (diagonal && !with_diagonals) continue;
        const double length = diagonal ? side_length_m * std::sqrt(2.0) : side_length_m;
        const double triangulated = (a->second - b->second).norm();
        if (triangulated > 0) ratios.push_back(length / triangulated);
      }
    }
  }
  if (ratios.empty()) return std::nullopt;
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  return ratios[ratios.size() / 2];
}

std::optional<double> ScaleToMarkers(Reconstruction* reconstruction, double max_error_px,
                                     double side_length_m) {
  const std::optional<double> ratio =
      MarkerScaleRatio(TriangulateMarkerCorners(*reconstruction, max_error_px), side_length_m,
                       /*with_diagonals=*/true);
  if (!ratio) return std::nullopt;
  const double scale = *ratio;
  for (auto& [id, pose] : reconstruction->mutable_poses()) pose.translation *= scale;
  std::vector<point3D_t> ids;
  for (const auto& [id, point] : reconstruction->points()) ids.push_back(id);
  for (point3D_t id : ids) reconstruction->point(id).xyz *= scale;
  // Rescaled, a point near a port may now lie inside it, and an adjustment
  // cannot start from its observations (OwnRenderFlatPortIntrinsicsUnknown:
  // a scale of 0.99928 put two points 1 cm inside a flat port).
  const int unprojectable = reconstruction->DeleteUnprojectableObservations();
  VLOG_IF(1, unprojectable > 0) << "scaled to the markers by " << scale << ": " << unprojectable
                                << " observations that cannot be projected any more deleted";
  return scale;
}

std::vector<MarkerCorner> UpdateMarkerCorners(const Reconstruction& reconstruction,
                                              double max_error_px,
                                              const std::vector<MarkerCorner>& adjusted) {
  std::map<std::pair<int, int>, Eigen::Vector3d> placed;
  for (const MarkerCorner& corner : adjusted)
    placed[{corner.marker_id, corner.corner}] = corner.xyz;
  std::vector<MarkerCorner> corners = TriangulateMarkerCorners(reconstruction, max_error_px);
  for (MarkerCorner& corner : corners) {
    const auto it = placed.find({corner.marker_id, corner.corner});
    if (it == placed.end()) continue;
    const bool agrees =
        std::all_of(corner.observations.begin(), corner.observations.end(), [&](const auto& seen) {
          const auto projected = reconstruction.CameraOf(seen.first)
                                     .Project(reconstruction.poses().at(seen.first) * it->second);
          return projected && (*projected - seen.second).norm() < max_error_px;
        });
    if (agrees) corner.xyz = it->second;
  }
  return corners;
}

camera_t CameraWithHousingAtBound(const std::map<camera_t, HousedCamera>& cameras) {
  for (const auto& [id, camera] : cameras) {
    if (camera.housing && camera.housing->AtBound()) return id;
  }
  return kInvalidCameraId;
}

}  // namespace portcal
