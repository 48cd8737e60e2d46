#include "pipelines/sfm/calibration_start.h"

#include <algorithm>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace portcal {

std::set<camera_t> StartFocalFromMarkers(const SfmInputs& inputs, std::optional<bool> mode,
                                         std::map<camera_t, HousedCamera>* cameras) {
  std::set<camera_t> set;
  if (mode == false) return set;
  for (auto& [camera_id, camera] : *cameras) {
    if (!mode && camera.camera.has_prior_focal_length) continue;
    std::vector<MarkerQuad> quads;
    for (const auto& [image_id, image] : inputs.images) {
      if (image.camera_id != camera_id) continue;
      for (const MarkerDetection& m : image.markers) quads.push_back({m.corners});
    }
    auto focal = FocalLengthFromMarkers(quads, camera.camera.PrincipalPointX(),
                                        camera.camera.PrincipalPointY());
    // The markers give the focal length the camera appears to have in
    // water (a flat port magnifies paraxial rays); bundle adjustment refines
    // the rest.
    if (focal && camera.housing) *focal *= camera.housing->InAirFocalRatio();
    if (!focal) {
      // The pairs may still give one (StartFocalFromPairs says if not).
      LOG(INFO) << "camera " << camera_id << ": " << quads.size()
                << " markers, too few for a focal length";
      continue;
    }
    LOG(INFO) << "camera " << camera_id << ": focal length from " << quads.size()
              << " markers: " << *focal << " px (was " << camera.camera.MeanFocalLength() << ")";
    for (int idx : CameraModelFocalLengthIdxs(camera.camera.model_id))
      camera.camera.params[idx] = *focal;
    set.insert(camera_id);
  }
  return set;
}

std::set<camera_t> StartFocalFromPairs(const SfmInputs& inputs, std::optional<bool> mode,
                                       const FocalStartOptions& options,
                                       const std::set<camera_t>& done,
                                       std::map<camera_t, HousedCamera>* cameras) {
  std::set<camera_t> set;
  if (mode == false) return set;
  for (auto& [camera_id, camera] : *cameras) {
    if (done.count(camera_id) || (!mode && camera.camera.has_prior_focal_length)) continue;
    std::string why_not;
    const auto start = EstimateFocalFromPairs(inputs, camera_id, camera, options, &why_not);
    if (!start) {
      LOG(WARNING) << "camera " << camera_id << ": no focal length from the markers or the pairs ("
                   << why_not << "); starting from " << camera.camera.MeanFocalLength()
                   << " px, judged only against what a lens could be";
      continue;
    }
    LOG(INFO) << "camera " << camera_id << ": focal length from " << start->num_pairs
              << " pairs' epipolar geometry: " << start->focal << " px (was "
              << camera.camera.MeanFocalLength() << "; 30 % away the cost is "
              << 1 + start->contrast << " times its minimum)";
    for (int idx : CameraModelFocalLengthIdxs(camera.camera.model_id))
      camera.camera.params[idx] = start->focal;
    set.insert(camera_id);
  }
  return set;
}

void StartRadialFromMatches(const SfmInputs& inputs, std::optional<bool> mode,
                            bool distortion_refined, const RadialStartOptions& options,
                            std::map<camera_t, HousedCamera>* cameras) {
  if (mode == false || (!mode && !distortion_refined)) return;
  for (auto& [camera_id, camera] : *cameras) {
    const std::vector<int> extra = CameraModelExtraParamsIdxs(camera.camera.model_id);
    const std::vector<double>& params =
        camera.camera.params;  // a lambda may not capture a binding (C++17)
    const bool undistorted =
        std::all_of(extra.begin(), extra.end(), [&params](int idx) { return params[idx] == 0; });
    // A fisheye model at k = 0 is the equidistant projection, near what
    // fisheye lenses are built to, where k = 0 of a pinhole model is far
    // from a wide angle's; and for a fisheye a focal length error is not
    // projective, so the search takes it up (docs/dev/auto_calibration_notes.md).
    const bool fisheye = CameraModelIsFisheye(camera.camera.model_id);
    if (!mode && (camera.camera.has_prior_focal_length || !undistorted || fisheye)) continue;
    const auto start = EstimateFirstRadialTerm(inputs, camera_id, camera, options);
    if (!start) {
      VLOG(1) << "camera " << camera_id
              << ": no first radial term from the matches (no such term or too few pairs)";
      continue;
    }
    LOG(INFO) << "camera " << camera_id << ": first radial term from " << start->num_matches
              << " matches of " << start->num_pairs << " pairs: " << start->k << " (epipolar RMS "
              << start->residual_px << " px; at the start " << start->residual_at_start_px
              << " px)";
    camera.camera.params[FirstRadialParamIdx(camera.camera)] = start->k;
  }
}

}  // namespace portcal
