// A live session's goal: the expected projection uncertainty at the working
// distance (mrcal's mean-frames measure, over the image's grid) down to a
// target, and what still limits it: corners of the image without points,
// too little tilt, too narrow a range of distances. Met, the page says
// "enough" and a hands-free session may finish by itself.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipelines/guidance/live_estimator.h"
#include "pipelines/live/hands_free.h"

namespace portcal {

struct LiveGoalOptions {
  // The mean expected projection uncertainty to reach, px (docs/live.md
  // argues the default).
  double target_uncertainty_px = 0.15;
  bool auto_finish = false;  // finish by itself once the goal is met
  void Check() const;        // throws OptionError naming the --Live. option
};

struct LiveGoal {
  double target_px = 0;
  bool determined = false;  // an uncertainty to compare yet
  double mean_px = 0, max_px = 0;
  bool met = false;
  double progress = 0;  // target / mean, at most 1
  // What the kept views still lack, in words ("the image's top-left corner
  // has no points"); informative once met.
  std::vector<std::string> limits;
  // "0.18 px of 0.15 px (83 %); still: ..." or "met: 0.12 px <= 0.15 px".
  std::string Summary() const;
};

// One camera's goal from its estimate and the kept views' corners
// (`image`: the frames' size).
LiveGoal EvaluateGoal(const LiveEstimate& estimate, const std::vector<CornerMap>& kept_corners,
                      cv::Size image, double target_px);

// A rig's: met when both cameras' are; the worse camera's figures, each
// camera's limits (camera 2's prefixed).
LiveGoal CombineGoals(const LiveGoal& camera1, const LiveGoal& camera2);

}  // namespace portcal
