// Where the mapper's intrinsics start when the camera's own are a guess:
// the focal length from the ArUco markers' shapes, the first radial term
// from the verified matches.
#pragma once

#include <map>
#include <optional>
#include <set>

#include "colmap_ext/camera/housed_camera.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/focal_start.h"
#include "pipelines/sfm/radial_start.h"

namespace portcal {

// A focal length this far from the markers' estimate (measured within
// 1-6 % of the truth on own and shared renders) is a wrong solution,
// whatever its standard deviation says.
constexpr double kMaxFocalRatioToMarkers = 1.25;

// Focal lengths from the markers of each camera's images (see
// FocalLengthFromMarkers), in-air equivalent behind a housing. `mode`:
// always (true), never (false), or for cameras without a prior focal length
// (nullopt). Returns the cameras it set.
std::set<camera_t> StartFocalFromMarkers(const SfmInputs& inputs, std::optional<bool> mode,
                                         std::map<camera_t, HousedCamera>* cameras);

// Focal lengths from the verified pairs (EstimateFocalFromPairs) of the
// cameras not in `done` (those the markers set); `mode` as above. Says
// (once per camera) why a camera keeps its guess. Returns the cameras it
// set.
std::set<camera_t> StartFocalFromPairs(const SfmInputs& inputs, std::optional<bool> mode,
                                       const FocalStartOptions& options,
                                       const std::set<camera_t>& done,
                                       std::map<camera_t, HousedCamera>* cameras);

// The first radial term of each camera from the matches
// (EstimateFirstRadialTerm). `mode`: always, never, or (nullopt) where the
// camera has no prior focal length, its distortion is all zero and
// `distortion_refined`, and the model is not a fisheye.
void StartRadialFromMatches(const SfmInputs& inputs, std::optional<bool> mode,
                            bool distortion_refined, const RadialStartOptions& options,
                            std::map<camera_t, HousedCamera>* cameras);

}  // namespace portcal
