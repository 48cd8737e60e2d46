// Auto-calibration's starts (auto_calibrator's policy): the mapper's
// models (sfm/model_mapping.h), the largest handed in memory to the
// refinement (model_refinement.h), judged against the ArUco markers' focal
// length. Where a start cannot be trusted (it fails, or its report carries a
// warning another start could cure), another initial pair and the mapper's
// random choices from the next seed take another path; the start with the
// fewest such warnings, then the smallest residual, is kept.
#pragma once

#include <optional>
#include <set>
#include <string>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/calibration/calibration_report.h"
#include "pipelines/refinement/model_refinement.h"
#include "pipelines/sfm/model_mapping.h"

namespace portcal {

struct CalibrationStartsOptions {
  // The first start's mapper (its random seed; start k maps with seed + k
  // and none of the earlier starts' initial pairs) and refinement.
  ModelMappingOptions map;
  ModelRefinementOptions refine;
  // The intrinsics are refined: judged against the markers' focal length,
  // and only then is more than one start tried.
  bool refine_intrinsics = true;
  int max_num_starts = 3;
  // Start 0 writes sparse/ (the mapper's models) and refined/ (the refined
  // model) here, start k into start_k/; the kept start's end up here.
  std::string output_path;
  std::string database_path;  // for messages
};

struct CalibrationStart {
  int index = 0;  // 0: written to output_path itself; k: output_path/start_k
  int num_registered = 0;
  ModelRefinementSummary refined;
  SparseModel model;  // refined
};

// The kept start (its files moved into output_path, the other starts'
// removed); throws the first start's NumericalError when none succeeds.
CalibrationStart BestStart(const CalibrationStartsOptions& options, const SfmInputs& inputs,
                           const std::optional<double>& markers_focal, ProgressSink& progress);

// The last look at a start whose intrinsics were refined: throws
// NumericalError when the focal length is far from the markers' estimate
// (`markers_focal`, the in-air focal length the ArUco markers give; a wrong
// solution however small its standard deviation), and adds warnings to the
// report for a poorly determined focal length.
void JudgeAutoCalibration(const std::optional<double>& markers_focal, CalibrationReport* report);

}  // namespace portcal
