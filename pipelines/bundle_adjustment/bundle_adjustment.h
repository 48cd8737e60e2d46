// Refractive bundle adjustment over a Reconstruction: poses, points and,
// optionally, intrinsics and housings, with the exact reprojection error or
// the virtual-camera error, a robust loss, and ArUco markers as scale: the
// marker corners are extra points, observed where they were detected, whose
// distances must equal the known side length (and diagonal).
#pragma once

#include <ceres/ceres.h>

#include <optional>
#include <set>
#include <vector>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

struct BundleAdjustmentOptions {
  bool refine_focal_length = false;
  bool refine_principal_point = false;
  bool refine_extra_params = false;
  // With refine_extra_params: only the first this many distortion
  // parameters (the radial terms come first in every model); -1: all.
  int max_num_extra_params = -1;
  bool refine_housing = false;
  // With refine_housing: the housing's position too (a flat port's
  // distance, a dome's centre; HousingRefinement::position), else only its
  // orientation (a flat port's normal).
  bool refine_housing_position = true;
  bool virtual_camera_error = false;  // else the exact reprojection error
  double sigma_px = 1.0;              // residuals in units of this
  bool scale_weighting = true;        // sigma grows with the keypoint's scale (above 2 px)
  double marker_sigma_px = 1.0;       // of an ArUco marker corner (edge-refined)
  double loss_scale = 1.0;            // Cauchy loss scale, in sigma; <= 0: no robust loss
  // The robust loss's weights rho'(|r|^2), taken at the starting residuals,
  // are held through the solve: a weighted least-squares problem, which
  // Gauss-Newton converges quadratically. The robust solve reweights at
  // every step and with the Cauchy loss converges only linearly (Ceres
  // models a residual's curvature by rho' alone where rho'' < 0), which
  // on a survey is a crawl of dozens of iterations (docs/benchmarks.md).
  // For a final solve whose inliers a robust solve has decided.
  bool hold_loss_weights = false;
  // > 0, with the robust loss (weights not held): the solve also ends once a
  // step changed the weight rho'(|r|^2) of at most this fraction of the
  // observations by more than 0.01: for a robust solve that only decides
  // the weights a held-weights solve then uses (weights_settled.h).
  double max_unsettled_weight_fraction = 0;
  // > 0: in global adjustments, the registered images' position priors are
  // residuals with this standard deviation (metres) and hold the gauge
  // (align the model to them first: AlignToPositionPriors).
  double position_prior_sigma_m = 0;
  int max_num_iterations = 100;
  double function_tolerance = 1e-8;  // relative cost change that ends the solve
  // Levenberg-Marquardt's first trust region (Ceres' default 1e4): its
  // damping is diag(J'J) / radius.
  double initial_trust_region_radius = 1e4;
  int num_threads = 2;
  void Check() const;  // throws OptionError naming --BundleAdjustment.*
  // These options with focal length, principal point and extra parameters
  // held (a stage that adjusts the housing under the current intrinsics).
  BundleAdjustmentOptions WithIntrinsicsHeld() const;
  // These options for the weighted least-squares solve after a robust solve
  // has decided the weights: the weights held, the first trust region
  // `first_trust_region_radius` (kHeldWeightsTrustRegionRadius below).
  BundleAdjustmentOptions WithWeightsHeld(double first_trust_region_radius) const;
};

// The held-weights solve's first trust region. Started near its minimum,
// the weighted problem converges in an undamped step; Ceres' default region
// (1e4) damps the long strips' weak modes over many steps
// (docs/scale.md: 2000 images, 4 steps against 1).
constexpr double kHeldWeightsTrustRegionRadius = 1e10;

// A physical marker corner: its point and where it was seen.
struct MarkerCorner {
  int marker_id = 0;
  int corner = 0;  // 0..3, OpenCV's order
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::vector<std::pair<image_t, Eigen::Vector2d>> observations;
};

struct MarkerScale {
  double side_length_m = 0;  // <= 0: markers do not constrain the scale
  double sigma_m = 0.0001;   // of each side and diagonal
  void Check() const;  // throws OptionError naming --Markers.side_length or --Markers.side_sigma
};

// Marker corners seen by at least two registered images, triangulated from
// the current poses (corners whose rays miss each other are dropped).
std::vector<MarkerCorner> TriangulateMarkerCorners(const Reconstruction& reconstruction,
                                                   double max_error_px);

// The median, over the markers' sides (0-1, 1-2, 2-3, 3-0) and with
// `with_diagonals` their diagonals (0-2, 1-3, known length side * sqrt 2),
// of known over triangulated length: the factor that brings `corners` to
// the markers' size. Nothing where no two corners of a marker make a side
// (or, with the diagonals, a diagonal).
std::optional<double> MarkerScaleRatio(const std::vector<MarkerCorner>& corners,
                                       double side_length_m, bool with_diagonals);

// Scales the model (points, camera centres; the origin stays) so that the
// markers' sides, triangulated from the current poses, have their known
// length: the median of known over triangulated length, over every side and
// diagonal of the corners TriangulateMarkerCorners finds. Returns that
// factor, or nothing (and nothing changed) where no marker has two corners
// triangulated. Observations that the rescale leaves unprojectable (a point
// now inside a port) are deleted, as an adjustment cannot start from them. The
// mapper's model otherwise grows at the scale refraction prefers under the
// housing's estimate of the moment (docs/scale.md: 2.7-3.7 times the
// markers'), and its adjustments, rather than rescale it, pull the corners
// off their rays, which the robust loss lets them do at little cost.
std::optional<double> ScaleToMarkers(Reconstruction* reconstruction, double max_error_px,
                                     double side_length_m);

// The corners for the next of a series of adjustments: triangulated afresh
// as above (corners newly seen by two images, the observations that agree),
// but a corner an earlier adjustment placed -- one of `adjusted` -- keeps
// that place wherever all its observations still agree with it. A fresh
// triangulation fits each corner to its rays alone and so undoes the
// adjustment's fit to the markers' sides (sigma 0.1 mm): millimetres of
// triangulation noise are tens of sigmas, which every adjustment would
// first have to remove again.
std::vector<MarkerCorner> UpdateMarkerCorners(const Reconstruction& reconstruction,
                                              double max_error_px,
                                              const std::vector<MarkerCorner>& adjusted);

struct BundleAdjustmentScope {
  // Images whose poses are free; all registered images when empty.
  std::set<image_t> variable_images;
  // Points to adjust; all points of the variable images when empty.
  bool all_points = true;
};

// Standard deviations of the cameras' and housings' parameters (0 for
// parameters held fixed): each the larger of two estimates, by the noise
// (the covariance of the solution scaled by the residual variance: every
// residual independent) and by the clusters' spread (the covariance
// clustered two ways, by image and by track, calibration_covariance.h: it
// grows when an image's errors share a cause, as a view-dependent keypoint
// bias does, or a track's, as the same texture seen from nearby views
// does). The first is the better estimate when the noise is what the model
// says, and the second, from a dozen images, is itself uncertain by ~20 %;
// the larger is wrong in the safe direction.
struct CalibrationStdDevs {
  std::map<camera_t, std::vector<double>> intrinsics;
  std::map<camera_t, std::vector<double>> housing;
  std::map<camera_t, std::vector<double>> intrinsics_by_noise, intrinsics_by_clusters;
  std::map<camera_t, std::vector<double>> housing_by_noise, housing_by_clusters;
  // Correlation of each intrinsic parameter (row) with each housing
  // parameter (column), 0 where either is held: near +-1 the data cannot
  // tell the two apart.
  std::map<camera_t, Eigen::MatrixXd> intrinsics_housing_correlation;
  double sigma0 = 0;  // estimated pixel noise (residual RMS corrected for the degrees of freedom)
  int64_t num_residuals = 0;
};

// COLMAP's bogus-camera test (min/max_focal_length_ratio 0.5 / 2,
// max_extra_param 1) of `after` against `before`; says why in `why`.
bool ImplausibleIntrinsics(const Camera& before, const Camera& after, std::string* why = nullptr);

// The first camera whose housing is at such a bound, or kInvalidCameraId.
camera_t CameraWithHousingAtBound(const std::map<camera_t, HousedCamera>& cameras);

// Adjusts in place. The gauge: the position priors (global adjustments with
// position_prior_sigma_m > 0 and priors spanning a plane), else the first
// registered image's pose is held, and, without marker scale, one
// translation coordinate of the second.
// Returns Ceres' summary; throws NumericalError if the solve fails.
ceres::Solver::Summary AdjustBundle(Reconstruction* reconstruction,
                                    const BundleAdjustmentOptions& options,
                                    const BundleAdjustmentScope& scope,
                                    std::vector<MarkerCorner>* markers,
                                    const MarkerScale& marker_scale,
                                    CalibrationStdDevs* std_devs = nullptr);

}  // namespace portcal
