// The parts of the incremental mapper's global adjustment that need none of
// the mapper's state: what an adjustment refines at a model's size, the
// test that undoes implausible intrinsics, and a snapshot to undo it with.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "colmap_ext/camera/housed_camera.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/incremental_mapper_options.h"

namespace portcal {

// Intrinsics from a handful of views are barely constrained: a global
// adjustment refines them from this many images on.
constexpr int kMinImagesForIntrinsics = 5;

// What ends a global adjustment (IncrementalMapperOptions::
// ba_global_max_unsettled_weights and ba_final_hold_weights).
enum class AdjustmentEnd {
  kCostChange,        // the cost change alone
  kGrowing,           // while the model grows: with the calibration held, also settled weights
  kWeightsSettled,    // settled weights or the cost change: it decides the inliers
  kHeldWeightsSolve,  // the weights held: the weighted least-squares solve after kWeightsSettled
};

// The options of a global adjustment of a model of `num_images` images:
// the intrinsics and housing refined as the mapper's options say when
// `refine_intrinsics`, only the first extra parameter below
// ba_full_intrinsics_min_images; ending as `end` says.
BundleAdjustmentOptions GlobalAdjustmentOptions(const IncrementalMapperOptions& options,
                                                int num_images, bool refine_intrinsics,
                                                AdjustmentEnd end = AdjustmentEnd::kCostChange);

// An adjustment ended on its own criterion rather than its iteration
// budget: the cost change (Ceres' CONVERGENCE) or settled robust weights
// (WeightsSettledCallback's USER_SUCCESS). What it moved is then a result.
bool EndedOnItsCriterion(const ceres::Solver::Summary& summary);

// The focal lengths any lens and port give, times the larger image side: a
// fisheye of 180 deg across a 16:9 frame's height has 0.18, a long lens a few.
constexpr double kMinPlausibleFocalFactor = 0.15;
constexpr double kMaxPlausibleFocalFactor = 5.0;

// COLMAP's bogus-camera test against the intrinsics before the adjustment,
// and the focal length against the mapper's start, which a slow drift of
// many adjustments would otherwise pass. A camera of `guessed_focal` (its
// start a guess, not data) has its focal length judged against what a lens
// could be (kMin/MaxPlausibleFocalFactor), not against the start or the
// last adjustment: refusing an answer for being far from a guess keeps the
// guess (a wide lens at 0.56 x the width against the 1.2 x default).
bool BogusIntrinsics(const std::map<camera_t, HousedCamera>& before,
                     const std::map<camera_t, HousedCamera>& after,
                     const std::map<camera_t, HousedCamera>& start, double max_focal_ratio_to_start,
                     const std::set<camera_t>& guessed_focal);

// The markers' corners for a global adjustment of `r` (markers of side
// `side_length_m`): the model scaled to them first (ScaleToMarkers) when a
// camera has a housing, as the priors' alignment puts it in their frame;
// then `corners` -- those an earlier adjustment placed, scaled with the
// model -- updated (UpdateMarkerCorners). Returns the scale applied (1 in
// air or without two views of a marker).
double PrepareMarkerCorners(Reconstruction* r, double max_error_px, double side_length_m,
                            std::vector<MarkerCorner>* corners);

// A housing with an orientation to refine apart from its position (a flat
// port's normal).
bool HasOrientedHousing(const Reconstruction& r);

// What an adjustment changes, as it was before: undone when the intrinsics
// came out implausible.
struct ModelSnapshot {
  std::map<camera_t, HousedCamera> cameras;
  std::map<image_t, Rigid3d> poses;
  std::map<point3D_t, Eigen::Vector3d> points;
  std::vector<MarkerCorner> markers;

  static ModelSnapshot Of(const Reconstruction& r, const std::vector<MarkerCorner>& markers);
  void Restore(Reconstruction* r, std::vector<MarkerCorner>* markers) const;
};

// " p0 p1 ..." of every camera's parameters; with `housings`, each
// camera's as " camera ... housing ...".
std::string CalibrationText(const Reconstruction& r, bool housings);

}  // namespace portcal
