// The matches radial_start and focal_start read their lens from: a
// camera's best-matched non-planar pairs (their matched pixels, evenly
// subsampled) and a fundamental matrix fitted robustly to a pair's points.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

using PixelMatches = std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>;  // in a, in b

// Sampson's squared distance of a correspondence x2' F x1 = 0 (infinite
// where F's lines degenerate).
double SampsonSquared(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2);

// The eight-point fit (Hartley-normalised, rank 2), reweighted three times
// by the Sampson denominator so that the algebraic fit approximates the
// geometric one, dropping what lies beyond three times the median residual:
// the verified inliers still hold a few wrong matches.
Eigen::Matrix3d FitFundamentalRobustly(const std::vector<Eigen::Vector2d>& x1,
                                       const std::vector<Eigen::Vector2d>& x2);

// The normalised coordinates (x/z, y/z) of the rays of a pair's matches
// through `camera` (and `housing`: the rays' directions in water). False
// when fewer than 16, or fewer than 95 %, of them have a ray ahead of the
// camera: a candidate lens that cannot turn the keypoints into rays is no
// candidate (the residuals of the rest would look better for having fewer
// points).
bool NormalisedRays(const PixelMatches& matches, const Camera& camera, const Housing* housing,
                    std::vector<Eigen::Vector2d>* x1, std::vector<Eigen::Vector2d>* x2);

// Up to `max_num_pairs` of the camera's pairs (both images its own, not
// planar), most inliers first, each with at least 16 matches, evenly
// subsampled to at most `max_matches_per_pair` (keeping their spread).
std::vector<PixelMatches> BestMatchedPairs(const SfmInputs& inputs, camera_t camera_id,
                                           int max_num_pairs, int max_matches_per_pair);

}  // namespace portcal
