#include "pipelines/synthetic/trajectory.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "colmap_ext/util/error.h"

namespace portcal {

void TrajectoryOptions::Check() const {
  if (!(fps > 0)) throw OptionError("trajectory.fps", fps, "> 0");
  if (num_pauses < 1) throw OptionError("trajectory.pauses", num_pauses, ">= 1");
  if (!(pause_seconds > 0)) throw OptionError("trajectory.pause_seconds", pause_seconds, "> 0 s");
  if (!(move_seconds > 0)) throw OptionError("trajectory.move_seconds", move_seconds, "> 0 s");
  if (!(exposure_s >= 0)) throw OptionError("trajectory.exposure", exposure_s, ">= 0 s");
}

namespace {

double Ease(double s) { return s * s * (3 - 2 * s); }

Rigid3d Between(const Rigid3d& a, const Rigid3d& b, double s) {
  // Interpolated as the target's pose seen from the camera: the target
  // turns about its own origin while it travels.
  return Rigid3d(a.rotation.slerp(s, b.rotation), (1 - s) * a.translation + s * b.translation);
}

// The camera's motion in its own frame between two nearby poses, per
// second: moved_from_cam = cam_from_target(t) * cam_from_target(t + h)^-1
// (the renderer's convention).
void Motion(const Rigid3d& now, const Rigid3d& later, double h, TrajectoryFrame* frame) {
  const Rigid3d moved_from_cam = now * later.Inverse();
  const Eigen::AngleAxisd turn(moved_from_cam.rotation);
  frame->angular_velocity_rad_s = turn.angle() * turn.axis() / h;
  frame->velocity_m_s = moved_from_cam.translation / h;
}

}  // namespace

std::vector<TrajectoryFrame> PlanTrajectory(const std::vector<Rigid3d>& key_poses,
                                            const TrajectoryOptions& options) {
  options.Check();
  std::vector<TrajectoryFrame> frames;
  const int pause_frames =
      std::max(1, static_cast<int>(std::lround(options.pause_seconds * options.fps)));
  const int move_frames =
      std::max(1, static_cast<int>(std::lround(options.move_seconds * options.fps)));
  for (size_t k = 0; k < key_poses.size(); ++k) {
    for (int f = 0; f < pause_frames; ++f) {
      TrajectoryFrame frame;
      frame.cam_from_target = key_poses[k];
      frame.pause = static_cast<int>(k);
      frames.push_back(frame);
    }
    if (k + 1 == key_poses.size()) break;
    for (int f = 1; f < move_frames; ++f) {
      const double s = static_cast<double>(f) / move_frames;
      TrajectoryFrame frame;
      frame.cam_from_target = Between(key_poses[k], key_poses[k + 1], Ease(s));
      const double ds = 1e-3;
      Motion(frame.cam_from_target, Between(key_poses[k], key_poses[k + 1], Ease(s + ds)),
             ds * options.move_seconds, &frame);
      frames.push_back(frame);
    }
  }
  return frames;
}

std::string TrajectoryYaml(const std::vector<TrajectoryFrame>& frames,
                           const TrajectoryOptions& options) {
  std::ostringstream out;
  out.precision(17);
  out << "# A hand-held target: held still in the pauses, moving between them.\nfps: "
      << options.fps << "\nexposure_s: " << options.exposure_s << "\nnum_frames: " << frames.size()
      << "\npauses:\n";
  for (size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].pause < 0 || (f > 0 && frames[f - 1].pause == frames[f].pause)) continue;
    size_t last = f;
    while (last + 1 < frames.size() && frames[last + 1].pause == frames[f].pause) ++last;
    const Rigid3d& pose = frames[f].cam_from_target;
    out << "  - {first_frame: " << f << ", last_frame: " << last
        << ", cam_from_target: {rotation_wxyz: [" << pose.rotation.w() << ", " << pose.rotation.x()
        << ", " << pose.rotation.y() << ", " << pose.rotation.z() << "], translation: ["
        << pose.translation.x() << ", " << pose.translation.y() << ", " << pose.translation.z()
        << "]}}\n";
  }
  return out.str();
}

}  // namespace portcal
