// The session's hands-free decisions: the still spells of every camera
// combined (and the sharpest moment of each kept), the spells that ended
// before they were tried said with what broke them, and whether a view
// repeats a kept (or refused) one. live_session.cc runs the loop.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "pipelines/live/live_session.h"

namespace portcal {

void LiveSession::RememberRefused(const std::vector<Sight>& sights) {
  KeptView refused;  // seen: the same still spell is not fitted again
  refused.corners = sights[0].corners;
  if (sights.size() > 1) refused.corners2 = sights[1].corners;
  rejected_.push_back(refused);
}

// A view is new when some camera sees the target elsewhere than in every
// kept (or refused) view. A refused view's repeat is not new either, and
// its reason was said when it was refused.
std::string LiveSession::NotNovel(const std::vector<Sight>& sights) const {
  const cv::Mat& image = sights[0].frame->image;
  const double novelty_px =
      options_.hands_free.novelty_fraction *
      std::hypot(static_cast<double>(image.cols), static_cast<double>(image.rows));
  for (const std::vector<KeptView>* seen : {&kept_, &rejected_}) {
    for (const KeptView& kept : *seen) {
      const double shift = MeanCornerShift(sights[0].corners, kept.corners);
      bool same = shift < novelty_px;
      if (sights.size() > 1)
        same = same && MeanCornerShift(sights[1].corners, kept.corners2) < novelty_px;
      if (!same) continue;
      if (seen == &rejected_) return "refused before";
      std::ostringstream why;
      why << std::fixed << std::setprecision(0) << "too close to the kept view " << kept.name
          << " (corners " << shift << " px from it on average, under " << novelty_px
          << " px: --Live.novelty)";
      return why.str();
    }
  }
  return "";
}

StillnessTracker::State LiveSession::Hold(const std::vector<Sight>& sights, double time_s,
                                          const std::string& lost_reason) {
  StillnessTracker::State hold;
  bool sharpest = false;
  for (size_t c = 0; c < sights.size(); ++c) {
    const StillnessTracker::State state = channels_[c].tracker.Update(
        time_s, sights[c].corners, CornerSharpness(sights[c].gray, sights[c].corners));
    if (c == 0) {
      hold = state;
      sharpest = state.sharpest;  // a rig's pair: camera 1's sharpest moment
      continue;
    }
    hold.still = hold.still && state.still;
    hold.new_spell = hold.new_spell || state.new_spell;
    hold.held_s = std::min(hold.held_s, state.held_s);
    hold.motion_px = std::max(hold.motion_px, state.motion_px);
    hold.ended_held_s = std::max(hold.ended_held_s, state.ended_held_s);
    hold.ended_motion_px = std::max(hold.ended_motion_px, state.ended_motion_px);
  }
  // Every camera's frame of one moment, so that a rig's pair stays a pair
  // (camera 1 chooses it; a spell begun anew by either camera restarts it).
  const bool all_seen = std::all_of(sights.begin(), sights.end(),
                                    [](const Sight& sight) { return !sight.corners.empty(); });
  if (all_seen && (sharpest || hold.new_spell)) {
    for (size_t c = 0; c < sights.size(); ++c) {
      Channel& channel = channels_[c];
      channel.sharpest.image = sights[c].frame->image.clone();
      channel.sharpest.time_s = sights[c].frame->time_s;
      channel.sharpest.index = sights[c].frame->index;
      channel.sharpest_gray = sights[c].gray.clone();
      channel.sharpest_corners = sights[c].corners;
    }
  }
  if (!hold.new_spell) return hold;
  // A spell held for half the time asked, ended before it was tried: the
  // person meant to hold this pose; say what broke it.
  if (options_.hands_free.enabled && !spell_tried_ &&
      hold.ended_held_s >= 0.5 * options_.hands_free.still_seconds) {
    std::ostringstream why;
    why << std::fixed << std::setprecision(1) << "held " << hold.ended_held_s << " s of "
        << options_.hands_free.still_seconds << " s (--Live.still_seconds), not kept: ";
    if (std::isinf(hold.ended_motion_px)) {
      why << "the target was lost" << (lost_reason.empty() ? "" : " (" + lost_reason + ")");
    } else {
      why << "it moved by " << hold.ended_motion_px << " px (--Live.still_px "
          << options_.hands_free.still_px << ")";
    }
    Note(why.str(), false);
  }
  spell_tried_ = false;
  return hold;
}

std::vector<LiveSession::Sight> LiveSession::SharpestSights() const {
  std::vector<Sight> sights;
  for (const Channel& channel : channels_)
    sights.push_back({&channel.sharpest, channel.sharpest_gray, channel.sharpest_corners});
  return sights;
}

}  // namespace portcal
