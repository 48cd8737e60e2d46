// A first value of the lens's first radial distortion term, from the
// verified matches, before any structure is built.
//
// Incremental SfM builds its first models on the rays of the starting
// intrinsics. With the distortion started at 0 and a strong lens (a wide
// angle with k1 = -0.3 behind a flat port), the periphery's rays are off by
// tens of pixels, the first global adjustment that frees the port tilts it
// to soak up the lens's distortion, and from there the intrinsics run into
// another basin (measured: k1 -> +1.0, f 905 -> 1906 px; see
// docs/dev/auto_calibration_notes.md). Radial distortion is what a projective
// two-view model cannot express (Fitzgibbon, "Simultaneous linear
// estimation of multiple view geometry and lens distortion", CVPR 2001):
// for each candidate k1 the matched keypoints are turned into rays through
// the camera and housing, a fundamental matrix is fitted on their
// normalised coordinates (it absorbs errors of the focal length and
// principal point, which are projective in air), and the k1 whose epipolar
// residuals are smallest over the best-matched pairs is kept. Behind a
// flat port a focal length error is not projective (refraction depends on
// the ray's angle) and leaks into k1 (own render, the markers' focal
// length 11 % low, k1 = 0: k1 +0.10); searching the focal length with k1
// was tried and fitted the start's principal point and tilt errors instead
// (synthetic test: f +25 %, k1 -0.41 for -0.30).
#pragma once

#include <optional>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

struct RadialStartOptions {
  double min_k = -0.6;  // search range of the first radial term
  double max_k = 0.6;
  int num_steps = 49;      // grid over the range, then a parabola at the best
  int max_num_pairs = 12;  // best-matched non-planar pairs of the camera
  int max_matches_per_pair = 600;
  void Check() const;  // throws OptionError naming --Mapper.init_radial_*
};

struct RadialStart {
  double k = 0;                     // the first radial term chosen
  double residual_px = 0;           // RMS epipolar (Sampson) residual there (trimmed), pixels
  double residual_at_start_px = 0;  // the same at the camera's own value
  int num_pairs = 0;
  int num_matches = 0;
};

// Index of the camera model's first radial term ("k1" or "k"), or -1.
int FirstRadialParamIdx(const Camera& camera);

// nullopt when the model has no radial term or fewer than two usable pairs.
std::optional<RadialStart> EstimateFirstRadialTerm(const SfmInputs& inputs, camera_t camera_id,
                                                   const HousedCamera& camera,
                                                   const RadialStartOptions& options);

}  // namespace portcal
