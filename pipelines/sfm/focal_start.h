// A focal length from the verified matches, before any structure is built,
// for a camera whose focal length is a guess and whose markers give none.
//
// The image reader's guess (1.2 x the larger side, COLMAP's default for
// ordinary lenses) is twice the focal length of the wide lenses in
// underwater housings; the mapper then starts far from the answer and its
// plausibility test refuses the answer itself. Here, for each candidate f
// on a log grid over the search range, the matched keypoints are turned
// into rays through the camera (and housing) with that focal length, a
// fundamental matrix is fitted to each pair's normalised coordinates, and
// its two non-zero singular values are compared: at the right f it is an
// essential matrix, whose two are equal (Mendonca and Cipolla, "A simple
// technique for self-calibration", CVPR 1999; cost (s1 - s2) / (s1 + s2),
// averaged over the best-matched pairs). Motions that do not tell f
// (translation alone, rotation about the optical axis, optical axes that
// meet at the same distance from both centres: Sturm's critical motions)
// leave the cost flat, and so does a strong distortion the camera does not
// yet have (the rays stay bent at every f); then no focal length is
// returned and the reason is said.
#pragma once

#include <optional>
#include <string>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

struct FocalStartOptions {
  // The search range, times the larger image side.
  double min_focal_factor = 0.3;
  double max_focal_factor = 2.0;
  int num_steps = 41;  // log grid over the range, then a parabola at the best
  int max_num_pairs = 30;
  int max_matches_per_pair = 300;
  // The cost 30 % away from the minimum on either side must exceed the
  // minimum by this factor minus one; a flatter cost does not tell f.
  double min_contrast = 1.0;
  void Check() const;  // throws OptionError naming --Mapper.init_focal_*
};

struct FocalStart {
  double focal = 0;     // px (both focal lengths of the model)
  double cost = 0;      // mean (s1 - s2) / (s1 + s2) there
  double contrast = 0;  // min(cost at f / 1.3, cost at 1.3 f) / cost - 1
  int num_pairs = 0;
  int num_matches = 0;
};

// nullopt, with the reason in `why_not`, when fewer than two pairs are
// usable, the best focal length lies at the search range's end, or the cost
// is too flat to tell.
std::optional<FocalStart> EstimateFocalFromPairs(const SfmInputs& inputs, camera_t camera_id,
                                                 const HousedCamera& camera,
                                                 const FocalStartOptions& options,
                                                 std::string* why_not);

}  // namespace portcal
