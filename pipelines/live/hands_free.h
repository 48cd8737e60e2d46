// Hands-free capture: a frame is kept when the target's corners have stayed
// still for a while (the person holds it), the frame is as sharp as the
// others of that still spell (no shake, no motion blur), and the view is
// new: its corners lie elsewhere in the image than those of every kept
// view. Once the camera is estimated the view must also lower the expected
// projection uncertainty by a margin (the live estimator says by how much).
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

namespace portcal {

struct HandsFreeOptions {
  bool enabled = true;            // else frames are kept only on request
  double still_px = 1.5;          // every corner within this of where the spell began, > 0
  double still_seconds = 0.7;     // for this long, > 0
  double min_sharpness = 0.85;    // of the sharpest frame of the spell, [0, 1]
  double novelty_fraction = 0.04; // mean corner shift from every kept view, of the image diagonal, >= 0
  double min_gain = 0.02;         // relative drop of the expected uncertainty, [0, 1)
  void Check() const;             // throws OptionError naming the --Live. option
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
    bool still = false;       // held for still_seconds
    bool sharp = false;       // and this frame is sharp enough to keep
    double held_s = 0;        // how long the spell has lasted
    double motion_px = 0;     // largest corner shift since the spell began
  };
  // This frame's corners (empty when the target is not seen).
  State Update(double time_s, const CornerMap& corners, double sharpness);
  // After a keep: the next keep needs a new spell.
  void Reset();

 private:
  HandsFreeOptions options_;
  CornerMap anchor_;
  double anchor_time_s_ = 0;
  double best_sharpness_ = 0;
};

}  // namespace portcal
