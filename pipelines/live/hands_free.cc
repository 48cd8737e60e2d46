#include "pipelines/live/hands_free.h"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/error.h"

namespace portcal {

void HandsFreeOptions::Check() const {
  if (!(still_px > 0)) throw OptionError("--Live.still_px", still_px, "> 0 px");
  if (!(still_seconds > 0)) throw OptionError("--Live.still_seconds", still_seconds, "> 0 s");
  if (!(novelty_fraction >= 0)) throw OptionError("--Live.novelty", novelty_fraction, ">= 0");
  if (!(min_gain >= 0 && min_gain < 1)) throw OptionError("--Live.min_gain", min_gain, "[0, 1)");
}

double MeanCornerShift(const CornerMap& a, const CornerMap& b) {
  double sum = 0;
  size_t shared = 0;
  for (const auto& [id, pixel] : a) {
    const auto it = b.find(id);
    if (it == b.end()) continue;
    sum += (pixel - it->second).norm();
    ++shared;
  }
  if (shared == 0 || 2 * shared < std::min(a.size(), b.size()))
    return std::numeric_limits<double>::infinity();
  return sum / static_cast<double>(shared);
}

double CornerSharpness(const cv::Mat& gray, const CornerMap& corners) {
  const int half = 4;
  double sum = 0;
  int count = 0;
  for (const auto& [id, pixel] : corners) {
    const int x = static_cast<int>(std::lround(pixel.x() - 0.5)),
              y = static_cast<int>(std::lround(pixel.y() - 0.5));
    if (x - half - 1 < 0 || y - half - 1 < 0 || x + half + 1 >= gray.cols ||
        y + half + 1 >= gray.rows)
      continue;
    cv::Mat laplacian;
    cv::Laplacian(gray(cv::Rect(x - half - 1, y - half - 1, 2 * half + 3, 2 * half + 3)), laplacian,
                  CV_32F);
    const cv::Mat inner = laplacian(cv::Rect(1, 1, 2 * half + 1, 2 * half + 1));
    sum += inner.dot(inner) / inner.total();
    ++count;
  }
  return count > 0 ? sum / count : 0;
}

StillnessTracker::State StillnessTracker::Update(double time_s, const CornerMap& corners,
                                                 double sharpness) {
  State state;
  const double lasted = anchor_.empty() ? 0 : last_time_s_ - anchor_time_s_;
  if (corners.empty()) {
    state.new_spell = true;
    if (!anchor_.empty()) {
      state.ended_held_s = lasted;
      state.ended_motion_px = std::numeric_limits<double>::infinity();
    }
    Reset();
    return state;
  }
  // Against each corner's mean over the spell: a hand's tremor wanders
  // about where the board is held, and the spell's first frame may be
  // anywhere in that wander.
  double motion = std::numeric_limits<double>::infinity();
  if (!anchor_.empty()) {
    motion = 0;
    size_t shared = 0;
    for (const auto& [id, pixel] : corners) {
      const auto it = anchor_.find(id);
      if (it == anchor_.end()) continue;
      motion = std::max(motion, (pixel - it->second / spell_frames_).norm());
      ++shared;
    }
    // A spell is the same corners held still: most of them seen throughout.
    if (10 * shared < 9 * std::max(anchor_.size(), corners.size()))
      motion = std::numeric_limits<double>::infinity();
  }
  last_time_s_ = time_s;
  if (!(motion <= options_.still_px)) {
    if (!anchor_.empty()) {
      state.ended_held_s = lasted;
      state.ended_motion_px = motion;
    }
    anchor_ = corners;
    spell_frames_ = 1;
    anchor_time_s_ = time_s;
    best_sharpness_ = sharpness;
    state.new_spell = true;
    state.sharpest = true;
    return state;
  }
  for (auto& [id, sum] : anchor_) {
    const auto it = corners.find(id);
    sum += it != corners.end() ? it->second
                               : sum / spell_frames_;  // a corner not seen stays where it was
  }
  ++spell_frames_;
  state.sharpest = sharpness > best_sharpness_;
  best_sharpness_ = std::max(best_sharpness_, sharpness);
  state.motion_px = motion;
  state.held_s = time_s - anchor_time_s_;
  state.still = state.held_s >= options_.still_seconds;
  return state;
}

void StillnessTracker::Reset() {
  anchor_.clear();
  spell_frames_ = 0;
  best_sharpness_ = 0;
}

}  // namespace portcal
