// Geometric verification of putative matches between two images, with
// COLMAP's decision rules (TwoViewGeometry in COLMAP 3.8): RANSAC for the
// essential matrix (on normalised rays of the calibrated cameras), the
// fundamental matrix and a homography; the configuration is
//   CALIBRATED when E explains >= min_E_F_inlier_ratio of F's inliers,
//   UNCALIBRATED when only F does,
//   PLANAR_OR_PANORAMIC when H explains > max_H_inlier_ratio of them,
//   DEGENERATE when nothing reaches min_num_inliers.
// F is found on all matches by OpenCV's USAC (LO-RANSAC with SPRT:
// Chum, Matas and Kittler, "Locally optimized RANSAC", DAGM 2003; Matas and
// Chum, "Randomized RANSAC with sequential probability ratio test", ICCV
// 2005), like COLMAP's LO-RANSAC: on a pair of unrelated images (~70 chance
// matches) the classic RANSAC ran its 10 000 trials in 80 ms, USAC ends in
// 9 ms. E and H are then searched among F's inliers, a clean set.
// Behind a housing the rays are not central, but over a pair's baseline the
// error of a central model is far below max_error (a few pixels), so the
// epipolar models still separate right matches from wrong ones.
#pragma once

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/feature/keypoint.h"
#include "colmap_ext/feature/two_view_geometry.h"

namespace portcal {

struct TwoViewVerificationOptions {
  double max_error = 4.0;  // pixels
  double confidence = 0.999;
  int max_num_trials = 10000;
  int min_num_inliers = 15;
  double min_inlier_ratio = 0.25;
  double min_E_F_inlier_ratio = 0.95;
  double max_H_inlier_ratio = 0.8;
  // E's and H's RANSAC draw from OpenCV's thread-local generator, whose
  // state otherwise depends on which thread verified which pairs before:
  // each call starts it from this seed, so the same matches give the same
  // geometry on any thread (F's USAC seeds itself, from a fixed state).
  int random_seed = 0;
  void Check() const;  // throws OptionError naming --TwoViewGeometry.*
};

TwoViewGeometry VerifyTwoView(const Camera& camera1, const FeatureKeypoints& keypoints1,
                              const Camera& camera2, const FeatureKeypoints& keypoints2,
                              const FeatureMatches& matches,
                              const TwoViewVerificationOptions& options);

}  // namespace portcal
