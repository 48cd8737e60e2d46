// Covariance of a bundle adjustment's calibration parameters with the 3-D
// points marginalised out: the Schur complement of the Gauss-Newton
// information matrix J'J on the non-point blocks (Triggs et al., "Bundle
// adjustment -- a modern synthesis", 2000, sec. 6). Each point's 3x3 block
// is pseudo-inverted, so a point whose depth the views do not fix (nearly
// parallel rays) adds no information instead of making the whole covariance
// rank deficient, as it does for Ceres' Covariance on the full problem.
// Only the rows of the inverse at the wanted parameters are formed.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace portcal {

// The covariance of some parameter blocks (the "wanted" ones), in their
// ambient coordinates: held coordinates of a manifold have zero variance.
struct MarginalCovariance {
  std::map<const double*, int> offset;  // row of each wanted block's first parameter
  std::map<const double*, int> size;    // its ambient size
  Eigen::MatrixXd covariance;           // the wanted blocks in order, scaled
  // The same blocks' cluster-robust ("sandwich") covariance, clustered two
  // ways, by image and by track (Cameron, Gelbach & Miller, "Robust
  // inference with multiway clustering", J. Bus. Econ. Stat. 2011):
  // V_image + V_track - V_image&track, each V_g = G/(G-1) * N/(N-K) *
  // S^-1 (sum_k u_k u_k') S^-1 with u_k the reduced gradient of cluster k's
  // residuals (Liang & Zeger, Biometrika 1986), negative eigenvalues of the
  // sum set to zero. It does not assume the residuals independent: errors
  // an image's observations share (blur, a view-dependent keypoint bias)
  // and errors a track's observations share (the same texture seen from
  // nearby views, biased alike beyond what the point absorbs) show up in
  // it, where the model covariance, which counts every residual as
  // independent information, stays small. Empty unless clusters were given.
  Eigen::MatrixXd clustered_covariance;
  int num_clusters = 0;  // images
  int num_tracks = 0;    // 0 when clustered by image only

  // Standard deviation of every ambient parameter of `block` by the model
  // covariance.
  std::vector<double> StdDevs(const double* block) const;
  // By the clustered covariance (empty when there is none).
  std::vector<double> ClusteredStdDevs(const double* block) const;
  // Correlation of parameter i of block a with parameter j of block b; 0
  // where either is held.
  double Correlation(const double* a, int i, const double* b, int j) const;
};

// How the residuals fall into clusters for the clustered covariance. A
// residual block's image is the cluster of the first of its parameter
// blocks in `image_of_block` (an image's pose, held or free); its track is
// the marginalised point it observes, else the first of its parameter
// blocks in `track_of_block` (a marker corner). A block with neither is a
// cluster of its own in that dimension (a marker's side length).
struct ResidualClusters {
  std::map<const double*, int> image_of_block;
  bool by_track = true;  // false: one-way, by image only
  std::map<const double*, int> track_of_block;
  double residuals_per_dof = 1;  // N / (N - K) of the whole adjustment
};

// `points`: 3-parameter blocks to marginalise (each residual may touch at
// most one of them); `others`: the remaining variable blocks (poses,
// intrinsics, housings, points shared by several-point residuals). Returns
// the covariance of `wanted` (a subset of `others`), scaled by `scale`^2
// (standard deviations by `scale`). Residuals are taken without the loss
// function (the clustered covariance weighs each block's gradient by the
// loss's derivative, as the solve did). Throws NumericalError when the
// reduced system is rank deficient, naming the parameter that dominates the
// unobservable direction by `describe(block, tangent index)`. The reduced
// system is decomposed densely up to `max_dense_size` tangent parameters
// (the rank test then finds the unobservable direction itself), beyond it
// by a sparse LDL' factorisation (a survey of thousands of images: the
// test names the parameter at the vanishing pivot). The residuals are
// linearised on `num_threads` threads.
MarginalCovariance ComputeMarginalCovariance(
    ceres::Problem* problem, const std::vector<double*>& points, const std::vector<double*>& others,
    const std::vector<const double*>& wanted, double scale,
    const std::function<std::string(const double*, int)>& describe,
    const ResidualClusters* clusters = nullptr, int max_dense_size = 1200, int num_threads = 1);

}  // namespace portcal
