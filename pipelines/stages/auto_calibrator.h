// `portcal auto_calibrator`: calibration without a known target, all the
// database stages in one command with defaults for a calibration object
// carrying ArUco markers: feature_extractor -> feature_masker ->
// exhaustive (or sequential) matcher, then refractive_mapper's and
// refractive_bundle_adjuster's cores (sfm/model_mapping.h,
// refinement/model_refinement.h), the model handed from one to the other in
// memory. Writes, under output_path: database.db, sparse/0 (the mapper's
// model), refined/ (the self-calibrated model) and, once, calibration.yaml /
// calibration.txt and report.html.
#pragma once

#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/refinement/calibration_starts.h"
#include "pipelines/refinement/model_refinement.h"
#include "pipelines/sfm/model_mapping.h"
#include "pipelines/stages/feature_extractor.h"
#include "pipelines/stages/feature_masker.h"
#include "pipelines/stages/feature_matcher.h"

namespace portcal {

struct AutoCalibratorOptions {
  std::string image_path;
  std::string output_path;
  std::string camera_model = "RADIAL";
  std::string camera_params;       // given: intrinsics known and held
  std::optional<Housing> housing;  // the housing to calibrate, with a first guess; none: in air
  std::string marker_dictionary = "DICT_4X4_50";
  MarkerScale marker_scale;  // side_length_m > 0: metric scale from the markers
  double mask_enlargement_factor = 3.0;
  bool mask = true;                                // keep only features near markers
  PairingMode matcher = PairingMode::kExhaustive;  // exhaustive or sequential
  SiftExtractionOptions sift;
  // Refine the intrinsics with the housing; nullopt: when camera_params is
  // empty.
  std::optional<bool> refine_intrinsics;
  // With the intrinsics refined: nullopt refines the principal point but
  // holds it at the image centre again unless it moves beyond 3 sigma (see
  // SelfCalibrationOptions::principal_point_test_sigmas); false
  // holds it; true refines it.
  std::optional<bool> refine_principal_point;
  // Seeds every random choice (RANSAC in verification and mapping): the
  // same images and options give the same calibration.
  int random_seed = 0;
  // The lens's first radial term from the matches before mapping
  // (ModelMappingOptions::init_radial_from_matches: not for fisheye
  // models): nullopt (where it applies) or false.
  std::optional<bool> init_radial_from_matches;
  // The focal length from the verified pairs where the markers give none
  // (ModelMappingOptions::init_focal_from_pairs): nullopt (when the
  // intrinsics are not given) or false.
  std::optional<bool> init_focal_from_pairs;
  // With the intrinsics refined: starts of the mapper and refinement (each
  // from the next random seed) while a start fails or its report carries
  // a warning; the start with the fewest warnings, then the smallest
  // residual, is kept (own render at a knife edge between two basins:
  // residual sigma 0.170 px in the right one, 0.275 in the wrong).
  int max_num_starts = 3;
  // Writes the calibrated camera (and housing) into output/database.db, so
  // that a next stage there (portcal's or COLMAP's) starts from them. Off by
  // default: a rerun into the same folder would start from them too.
  bool update_database = false;
  int num_threads = 2;
  void Check() const;  // throws OptionError naming the option
};

struct AutoCalibratorSummary {
  ModelRefinementSummary refined;
  int num_images = 0;
  int num_registered = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;
};

AutoCalibratorSummary RunAutoCalibrator(const AutoCalibratorOptions& options,
                                        ProgressSink& progress);

}  // namespace portcal
