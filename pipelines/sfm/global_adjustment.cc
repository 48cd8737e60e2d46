#include "pipelines/sfm/global_adjustment.h"

#include <algorithm>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

BundleAdjustmentOptions GlobalAdjustmentOptions(const IncrementalMapperOptions& options,
                                                int num_images, bool refine_intrinsics,
                                                AdjustmentEnd end) {
  BundleAdjustmentOptions ba;
  ba.refine_focal_length = refine_intrinsics && options.ba_refine_focal_length;
  ba.refine_principal_point = refine_intrinsics && options.ba_refine_principal_point;
  ba.refine_extra_params = refine_intrinsics && options.ba_refine_extra_params;
  if (num_images < options.ba_full_intrinsics_min_images) {
    ba.max_num_extra_params = 1;
  }
  ba.refine_housing = refine_intrinsics && options.ba_refine_housing;
  ba.max_num_iterations = options.ba_max_num_iterations;
  ba.function_tolerance = options.ba_global_function_tolerance;
  ba.num_threads = options.num_threads;
  // While growing, with the calibration held the adjustment only carries
  // the model along until the next one; one that refines the calibration
  // converges (it decides whether the port has settled).
  if ((end == AdjustmentEnd::kGrowing && !refine_intrinsics) ||
      end == AdjustmentEnd::kWeightsSettled) {
    ba.max_unsettled_weight_fraction = options.ba_global_max_unsettled_weights;
  }
  if (end == AdjustmentEnd::kHeldWeightsSolve)
    return ba.WithWeightsHeld(kHeldWeightsTrustRegionRadius);
  return ba;
}

bool EndedOnItsCriterion(const ceres::Solver::Summary& summary) {
  return summary.termination_type == ceres::CONVERGENCE ||
         summary.termination_type == ceres::USER_SUCCESS;
}

bool BogusIntrinsics(const std::map<camera_t, HousedCamera>& before,
                     const std::map<camera_t, HousedCamera>& after,
                     const std::map<camera_t, HousedCamera>& start, double max_focal_ratio_to_start,
                     const std::set<camera_t>& guessed_focal) {
  for (const auto& [id, camera] : after) {
    if (guessed_focal.count(id)) {
      const double side = static_cast<double>(std::max(camera.camera.width, camera.camera.height));
      const double factor = camera.camera.MeanFocalLength() / side;
      if (!(factor > kMinPlausibleFocalFactor && factor < kMaxPlausibleFocalFactor)) return true;
      // The distortion still against COLMAP's bound.
      Camera reference = before.at(id).camera;
      for (const int idx : CameraModelFocalLengthIdxs(reference.model_id))
        reference.params[idx] = camera.camera.params[idx];
      if (ImplausibleIntrinsics(reference, camera.camera)) return true;
      continue;
    }
    if (ImplausibleIntrinsics(before.at(id).camera, camera.camera)) return true;
    const double ratio = camera.camera.MeanFocalLength() / start.at(id).camera.MeanFocalLength();
    if (!(ratio < max_focal_ratio_to_start && 1 / ratio < max_focal_ratio_to_start)) return true;
  }
  return false;
}

double PrepareMarkerCorners(Reconstruction* r, double max_error_px, double side_length_m,
                            std::vector<MarkerCorner>* corners) {
  // In air the scale is a gauge that the refinement sets from the markers;
  // rescaling earlier only changed which minimum the intrinsics reached from
  // a poor start (AutoCalibrationRealCameras' in-air target: focal length
  // 10 px, 3 sigma, off). Behind a housing refraction sets the scale.
  const bool refracted = AnyHoused(r->cameras());
  const double scale =
      refracted ? ScaleToMarkers(r, max_error_px, side_length_m).value_or(1.0) : 1.0;
  VLOG(2) << "global adjustment: " << r->poses().size() << " images scaled by " << scale
          << " to the markers";
  for (MarkerCorner& corner : *corners) corner.xyz *= scale;
  *corners = UpdateMarkerCorners(*r, max_error_px, *corners);
  return scale;
}

bool HasOrientedHousing(const Reconstruction& r) {
  return std::any_of(r.cameras().begin(), r.cameras().end(), [](const auto& entry) {
    return entry.second.housing && !entry.second.housing->Refinement().orientation.empty();
  });
}

ModelSnapshot ModelSnapshot::Of(const Reconstruction& r, const std::vector<MarkerCorner>& markers) {
  ModelSnapshot snapshot;
  snapshot.cameras = r.cameras();
  snapshot.poses = r.poses();
  for (const auto& [id, point] : r.points()) snapshot.points[id] = point.xyz;
  snapshot.markers = markers;
  return snapshot;
}

void ModelSnapshot::Restore(Reconstruction* r, std::vector<MarkerCorner>* markers) const {
  r->mutable_cameras() = cameras;
  r->mutable_poses() = poses;
  for (const auto& [id, xyz] : points) r->point(id).xyz = xyz;
  r->UpdateRays();
  *markers = this->markers;
}

std::string CalibrationText(const Reconstruction& r, bool housings) {
  std::ostringstream values;
  for (const auto& [id, camera] : r.cameras()) {
    if (housings) values << " camera";
    for (const double p : camera.camera.params) values << " " << p;
    if (housings && camera.housing) {
      values << " housing";
      for (const double p : camera.housing->params) values << " " << p;
    }
  }
  return values.str();
}

}  // namespace portcal
