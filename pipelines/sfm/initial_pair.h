// The two-view start of incremental structure-from-motion on refracted
// rays (Schoenberger & Frahm, "Structure-from-motion revisited", CVPR 2016,
// sec. 4.2): which pairs to try first, and a model of two images from one
// of them.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/incremental_mapper_options.h"

namespace portcal {

// Pairs of images not in `used` nor `tried` with at least
// `options.init_min_num_inliers` verified matches, best first: most inlier
// matches first, but pairs whose geometry is a homography last and, when
// markers of known side give the scale and a camera of `cameras` (the
// mapper's start) is behind a housing, the best of the pairs that see a
// marker in common and are not homographies (half of
// `options.init_max_num_trials` at most) before all others.
std::vector<image_pair_t> RankInitialPairs(const SfmInputs& inputs,
                                           const std::map<camera_t, HousedCamera>& cameras,
                                           const IncrementalMapperOptions& options,
                                           const std::set<image_t>& used,
                                           const std::set<image_pair_t>& tried);

// Registers `a` at the origin and `b` by the relative pose of their matched
// rays (a generalised relative pose in RANSAC), scaled to
// `options.init_scene_depth_m` or, with markers of known side, to the
// markers both see, and adds the points triangulated from both within
// `options.init_max_error_px`. False, with `r` as it was, when the pair has
// too few matches or inliers, too small a triangulation angle, or too few
// points.
bool StartFromPair(const IncrementalMapperOptions& options, image_t a, image_t b,
                   Reconstruction* r);

}  // namespace portcal
