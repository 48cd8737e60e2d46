// The projection difference of two lens calibrations, as mrcal defines it
// (mrcal.projection_diff, "differencing" in mrcal's docs): grid the imager,
// unproject each grid pixel with camera A to a ray at infinity, rotate the
// rays by the rotation that best aligns A's frame with B's (two calibrations
// of one lens may disagree on where the optical axis points without
// disagreeing on the lens; mrcal's fit: least squares on the weighted
// squared angle between the rays), project with B, and measure the pixel
// distance.
//
// With both covariances given, the fit weighs every grid point by
// 1 / (sigma_A sigma_B)^2 over the whole imager (mrcal's choice when it has
// uncertainties), and the difference the covariances predict is propagated
// through the whole computation, fit included (first order, by central
// differences): E|diff|^2 = tr(J_A C_A J_A^T) + tr(J_B C_B J_B^T). Without
// covariances the fit uses mrcal's default focus region, a circle of radius
// min(width, height) / 6 at the image centre.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "colmap_ext/camera/camera.h"

namespace portcal {

struct CalibratedLens {
  Camera camera;
  Eigen::MatrixXd covariance;  // of camera.params; empty if unknown
};

struct ProjectionDiffOptions {
  int gridn_width = 60;      // grid points across; rows follow the aspect ratio
  double focus_radius = -1;  // px; < 0: mrcal's default (see above)
  void Check() const;        // throws OptionError
};

struct ProjectionDiff {
  int grid_width = 0, grid_height = 0;
  std::vector<Eigen::Vector2d> pixels;  // grid, row-major, COLMAP pixels
  std::vector<double> diff_px;          // NaN where a projection failed
  std::vector<double> predicted_px;     // sqrt(E|diff|^2); empty without covariances
  Eigen::Matrix3d b_from_a = Eigen::Matrix3d::Identity();
  double mean_px = 0, p95_px = 0, max_px = 0;
  double predicted_mean_px = 0, predicted_p95_px = 0;  // 0 without covariances
  std::string worst_region;                            // e.g. "top-left corner" (of a 3 x 3 split)
  double worst_region_mean_px = 0;
};

// Both cameras must have the same image size. Throws InputError otherwise,
// NumericalError when too few grid points project.
ProjectionDiff ComputeProjectionDiff(const CalibratedLens& a, const CalibratedLens& b,
                                     const ProjectionDiffOptions& options);

// Heat map of diff_px over the image (colour bar in px, the worst region
// outlined), written atomically as PNG.
void WriteProjectionDiffHeatMap(const ProjectionDiff& diff, int width, int height,
                                const std::string& title, const std::filesystem::path& path);

}  // namespace portcal
