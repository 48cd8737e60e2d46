// A person's hand-held calibration as a video: the target held still at a
// few poses, carried smoothly from one to the next in between (with the
// motion blur of that movement), at a frame rate. `portcal synthesize`
// renders it as frames and as a video file, the source a live calibration
// is tested on.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"

namespace portcal {

struct TrajectoryOptions {
  double fps = 10;             // frames per second, > 0
  int num_pauses = 4;          // poses the target is held still at, >= 1
  double pause_seconds = 1.5;  // how long each is held, > 0
  double move_seconds = 1.0;   // carrying the target to the next one, > 0
  double exposure_s = 0.02;    // motion blur while moving, >= 0
  bool video = true;           // also trajectory.avi (Motion JPEG)
  void Check() const;          // throws OptionError naming the key
};

struct TrajectoryFrame {
  Rigid3d cam_from_target;
  // The camera's motion in its own frame (the renderer's motion blur).
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  int pause = -1;  // index of the held pose, -1 while moving
};

// Holds each key pose for pause_seconds, moving between them with a smooth
// start and stop (slerp and lerp eased by 3s^2 - 2s^3).
std::vector<TrajectoryFrame> PlanTrajectory(const std::vector<Rigid3d>& key_poses,
                                            const TrajectoryOptions& options);

// trajectory.yaml: the frame rate and each pause's first and last frame
// (0-based, as the frames' order) and its pose.
std::string TrajectoryYaml(const std::vector<TrajectoryFrame>& frames,
                           const TrajectoryOptions& options);

}  // namespace portcal
