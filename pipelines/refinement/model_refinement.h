// The self-calibration of a sparse model with its report: the core that
// refractive_bundle_adjuster wraps with files and auto_calibrator calls on
// the mapper's model in memory. The model is aligned to its scale (the
// images' position priors, or the ArUco markers' corners triangulated),
// adjusted on SelfCalibration's schedule (a housing left at a bound by the
// mapper started again from the guess, the intrinsics first), and reported
// for its first camera: parameters and standard deviations, RMS, what the
// views cannot tell apart, the verdict.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/io/sparse_model.h"
#include "pipelines/bundle_adjustment/self_calibration.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/reconstruction/reconstruction.h"

namespace portcal {

// The schedule's options (ba, marker_scale, the IRLS tolerances, the
// principal point test) are SelfCalibrationOptions'.
struct ModelRefinementOptions : SelfCalibrationOptions {
  std::optional<Housing> housing;  // replaces the model's housings
  // The first guess of the housing, for one case only: the model's own
  // housing lies at a bound of the adjustment (a flat port's distance at its
  // 0.1 mm floor, a dome decentred to 90 % of its radius; the mapper can
  // slide it there). With intrinsics and housing refined, the adjustment
  // then starts its bound parameters (flat: distance; dome: centre) from
  // this guess, the rest (a flat port's normal) from the model, and adjusts
  // the intrinsics first. auto_calibrator passes its --Housing.*.
  std::optional<Housing> housing_guess;
};

// Where the model comes from.
struct ModelSource {
  std::string model_name;     // for messages: the input path
  std::string database_name;  // for messages: where markers and priors come from
  // The model; called again for a second attempt (see LoadAlignedModel).
  std::function<SparseModel()> load_model;
  // Adds to an image of the model (keypoints only) its marker detections,
  // position prior and keypoint scales; empty: none.
  std::function<void(SfmImage*)> add_extras;
};

// What the mapper's or the database's image of the same name (`read`:
// keypoints with scales, markers, position prior) adds to `image`, an image
// of a model that holds keypoints only: its markers and prior, and the
// scales where the model's points are `read`'s keypoints (each within
// 1e-3 px; a model from elsewhere keeps no scales). For add_extras.
void AddExtrasOf(const SfmImage& read, SfmImage* image);

struct ModelRefinementSummary {
  CalibrationReport report;  // of the first camera, with its verdict
  int num_marker_corners = 0;
  int num_position_priors = 0;  // images whose priors fixed the frame
  int num_filtered = 0;
  bool principal_point_held = false;  // by principal_point_test_sigmas
  // Of report.warnings, those about what the views' geometry cannot tell
  // apart (an intrinsic and a housing parameter traded): another start on
  // the same views cannot cure them.
  int num_geometry_warnings = 0;
};

struct RefinedModel {
  SparseModel model;  // adjusted
  ModelRefinementSummary summary;
};

RefinedModel RefineModel(const ModelRefinementOptions& options, const ModelSource& source);

}  // namespace portcal
