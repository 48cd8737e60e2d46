// Hands-free capture: a pose is kept when the target's corners have stayed
// still for a while (the person holds it), as the sharpest frame of that
// still spell (no shake, no motion blur), and when the view is new: its
// corners lie elsewhere in the image than those of every kept view. Once
// the camera is estimated the view must also lower the expected projection
// uncertainty by a margin (the live estimator says by how much). Every
// still pose is tried once; what is not kept is said, with the reason.
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

namespace portcal {

struct HandsFreeOptions {
  bool enabled = true;         // else frames are kept only on request
  double still_px = 3;         // every corner within this of its mean over the spell, > 0
  double still_seconds = 0.7;  // for this long, > 0
  double novelty_fraction =
      0.04;                // mean corner shift from every kept view, of the image diagonal, >= 0
  double min_gain = 0.01;  // relative drop of the expected uncertainty, [0, 1)
  void Check() const;      // throws OptionError naming the --Live. option
};

using CornerMap = std::map<int, Eigen::Vector2d>;  // point id -> pixel

// Mean distance of the corners two views share; infinite when they share
// fewer than half of the smaller view's corners.
double MeanCornerShift(const CornerMap& a, const CornerMap& b);

// Focus at the corners: the mean squared Laplacian in small windows around
// them (blur of any kind lowers it).
double CornerSharpness(const cv::Mat& gray, const CornerMap& corners);

class StillnessTracker {
 public:
  explicit StillnessTracker(const HandsFreeOptions& options) : options_(options) {}

  struct State {
    bool still = false;      // held for still_seconds
    bool sharpest = false;   // this frame is the spell's sharpest so far
    bool new_spell = false;  // this frame begins a spell (or the target is not seen)
    double held_s = 0;       // how long the spell has lasted
    double motion_px = 0;    // largest corner shift since the spell began
    // The spell this frame ended, by motion or by losing the target: how
    // long it had lasted and the motion that ended it (infinite: lost).
    double ended_held_s = 0;
    double ended_motion_px = 0;
  };
  // This frame's corners (empty when the target is not seen).
  State Update(double time_s, const CornerMap& corners, double sharpness);
  // The next frame begins a new spell.
  void Reset();

 private:
  HandsFreeOptions options_;
  CornerMap anchor_;  // each corner's sum over the spell's frames
  int spell_frames_ = 0;
  double anchor_time_s_ = 0;
  double last_time_s_ = 0;
  double best_sharpness_ = 0;
};

}  // namespace portcal
