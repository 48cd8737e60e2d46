// `portcal pose_suggester`: where to hold the target next, from what a
// database holds so far (planning a dive, or the next session at the
// tank): the next N poses as cam_from_target and as pictures of where the
// target must appear in the image.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/guidance/live_estimator.h"

namespace portcal {

struct PoseSuggesterOptions {
  std::string database_path;
  std::string output_path;  // suggested_poses.txt, suggested_pose_NN.png
  int camera_id = -1;       // -1: the only camera with views (or the only camera)
  // Housing calibration: the in-air calibration.yaml and the port.
  std::string input_calibration;
  std::optional<Housing> housing;
  std::vector<std::string> fixed_params;
  TargetDetectorOptions target;  // the target (--Target.*)
  NextPoseOptions guidance;
  int num_poses = 5;
  void Check() const;  // throws OptionError naming the option
};

struct PoseSuggesterSummary {
  LiveEstimate estimate;  // from the views in the database
  std::vector<PoseSuggestion> poses;
};

// Reads the database only. Throws InputError (no camera, no input
// calibration for a housing), NumericalError (no pose fits the ranges).
PoseSuggesterSummary RunPoseSuggester(const PoseSuggesterOptions& options, ProgressSink& progress);

}  // namespace portcal
