// Two sources of a stereo rig, paired by time. Recorded sources (files,
// folders) pair by their media time; live ones (devices, streams) by when
// each frame arrived, as unsynchronised cameras give nothing better. A
// frame with no partner within the tolerance is dropped (the older one), so
// a pair never mixes two moments of a moving target.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "pipelines/live/frame_source.h"

namespace portcal {

struct FramePair {
  Frame first, second;
  double offset_s = 0;  // |time of first - time of second|
};

class FramePairSource {
 public:
  // `tolerance_s` <= 0: half the frame interval of the slower source.
  // Throws InputError naming the source that cannot be opened, or when one
  // source is live and the other recorded (their clocks do not compare).
  FramePairSource(const FrameSourceOptions& first, const FrameSourceOptions& second,
                  double tolerance_s);

  // kEnd when either source ends, kStalled when either stalls.
  FrameStatus Next(FramePair* pair);

  double tolerance_s() const { return tolerance_s_; }
  int64_t dropped() const { return dropped_; }  // frames without a partner
  std::string Describe() const;
  const FrameSource& first() const { return *first_; }
  const FrameSource& second() const { return *second_; }

 private:
  double Clock(const FrameSource& source, const Frame& frame) const;

  std::unique_ptr<FrameSource> first_, second_;
  std::optional<Frame> pending_first_, pending_second_;
  double tolerance_s_ = 0;
  int64_t dropped_ = 0;
};

}  // namespace portcal
