// Position priors (navigation: DVL/INS, USBL, GPS) as the metric frame of a
// reconstruction. Refraction through a flat port observes scale only weakly
// (the port distance and the scene scale trade off exactly for a thin
// interface), so a survey without markers takes its scale from where the
// vehicle says the camera was: the model is first aligned to the priors by
// a similarity (Umeyama, "Least-squares estimation of transformation
// parameters between two point patterns", PAMI 1991) and the priors then
// join the bundle adjustment as residuals on the camera centres, which also
// hold the gauge.
#pragma once

#include <ceres/ceres.h>

#include <optional>

#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

// x_new = scale * rotation * x_old + translation.
struct Similarity3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

// The similarity that best maps the columns of `from` onto those of `to`
// (Umeyama, least squares, with scale).
Similarity3d FitSimilarity(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to);

struct PositionPriorAlignment {
  Similarity3d new_from_old;
  int num_priors = 0;   // registered images with a prior
  int num_inliers = 0;  // used in the final fit
  double rms_m = 0;     // of the inliers' centre - prior after the fit
  // Observations the move left unprojectable, deleted (see below).
  int num_unprojectable_deleted = 0;
};

// Aligns the reconstruction (poses and points) to its registered images'
// position priors. A first fit on all, then again on those within
// max(3 x the robust spread, min_inlier_distance_m) of their prior (a
// navigation fix can jump). Observations whose point no longer projects
// into its image after the move (a point now inside a port) are deleted:
// an adjustment cannot start from them. nullopt, and nothing changed, when
// fewer than three images have priors or their centres are (nearly)
// collinear.
std::optional<PositionPriorAlignment> AlignToPositionPriors(Reconstruction* reconstruction,
                                                            double min_inlier_distance_m);

// Number of registered images with a position prior that span a plane or a
// volume (so that they fix a similarity): the count, 0 when degenerate.
int NumUsablePositionPriors(const Reconstruction& reconstruction);

// Residual (centre - prior) / sigma on a pose block (quaternion x, y, z, w;
// translation) of cam_from_world: centre = -R^T t.
ceres::CostFunction* CreatePositionPriorCost(const Eigen::Vector3d& prior, double sigma_m);

}  // namespace portcal
