#include "pipelines/live/live_goal.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "pipelines/calibration/calibration_verdict.h"

namespace portcal {

void LiveGoalOptions::Check() const {
  if (!(target_uncertainty_px > 0)) {
    throw OptionError("--Live.target_uncertainty_px", target_uncertainty_px, "> 0 px");
  }
}

namespace {

constexpr double kWantedTiltDeg = 30;         // views tilted at least this (a board's depth range)
constexpr double kWantedDistanceRatio = 1.4;  // farthest / nearest kept view

// Image corners (of a 3 x 3 split) that no kept view's corner falls in.
std::vector<std::string> EmptyImageCorners(const std::vector<CornerMap>& kept, cv::Size image) {
  std::vector<Eigen::Vector2d> pixels;
  for (const CornerMap& corners : kept) {
    for (const auto& [id, xy] : corners) pixels.push_back(xy);
  }
  return portcal::EmptyImageCorners(image.width, image.height, pixels);
}

}  // namespace

std::string LiveGoal::Summary() const {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3);
  if (!determined) {
    text << "goal " << target_px << " px: no uncertainty yet";
  } else if (met) {
    text << "enough: expected projection uncertainty " << mean_px << " px <= " << target_px
         << " px (Finish)";
  } else {
    text << "expected projection uncertainty " << mean_px << " px, goal " << target_px << " px ("
         << std::setprecision(0) << 100 * progress << " %)";
  }
  if (!limits.empty())
    text << (met ? "; could still improve: " : "; still limiting: ") << JoinedWords(limits);
  return text.str();
}

LiveGoal EvaluateGoal(const LiveEstimate& estimate, const std::vector<CornerMap>& kept_corners,
                      cv::Size image, double target_px) {
  LiveGoal goal;
  goal.target_px = target_px;
  goal.determined =
      estimate.solved && estimate.uncertainty.determined && estimate.uncertainty.mean_px > 0;
  if (goal.determined) {
    goal.mean_px = estimate.uncertainty.mean_px;
    goal.max_px = estimate.uncertainty.max_px;
    goal.met = goal.mean_px <= target_px;
    goal.progress = std::min(1.0, target_px / goal.mean_px);
  }
  if (image.area() > 0) {
    const std::vector<std::string> empty = EmptyImageCorners(kept_corners, image);
    if (!empty.empty()) {
      goal.limits.push_back("the image's " + JoinedWords(empty) + " corner" +
                            (empty.size() > 1 ? "s have" : " has") +
                            " no points (bring the target there)");
    }
  }
  double max_tilt = 0, nearest = 1e300, farthest = 0;
  for (const Rigid3d& pose : estimate.view_poses) {
    // The board's normal against its line of sight.
    const Eigen::Vector3d normal = pose.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d sight = pose.translation.normalized();
    max_tilt =
        std::max(max_tilt, std::acos(std::min(1.0, std::abs(normal.dot(sight)))) * 180 / M_PI);
    nearest = std::min(nearest, pose.translation.norm());
    farthest = std::max(farthest, pose.translation.norm());
  }
  if (!estimate.view_poses.empty()) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(0);
    if (max_tilt < kWantedTiltDeg) {
      text << "tilts up to " << max_tilt << " deg (tilt the target " << kWantedTiltDeg
           << "-45 deg, both ways)";
      goal.limits.push_back(text.str());
      text.str("");
    }
    if (farthest < kWantedDistanceRatio * nearest) {
      text << std::setprecision(2) << "distances " << nearest << "-" << farthest
           << " m only (hold it nearer and farther)";
      goal.limits.push_back(text.str());
    }
  }
  return goal;
}

LiveGoal CombineGoals(const LiveGoal& camera1, const LiveGoal& camera2) {
  LiveGoal goal = camera1;
  goal.determined = camera1.determined && camera2.determined;
  goal.met = camera1.met && camera2.met;
  goal.mean_px = std::max(camera1.mean_px, camera2.mean_px);
  goal.max_px = std::max(camera1.max_px, camera2.max_px);
  goal.progress = std::min(camera1.progress, camera2.progress);
  for (std::string& limit : goal.limits) limit = "camera 1: " + limit;
  for (const std::string& limit : camera2.limits) goal.limits.push_back("camera 2: " + limit);
  return goal;
}

}  // namespace portcal
