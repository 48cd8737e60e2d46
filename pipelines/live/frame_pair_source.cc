#include "pipelines/live/frame_pair_source.h"

#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {

FramePairSource::FramePairSource(const FrameSourceOptions& first, const FrameSourceOptions& second,
                                 double tolerance_s)
    : first_(std::make_unique<FrameSource>(first)), second_(std::make_unique<FrameSource>(second)) {
  if (first_->live() != second_->live()) {
    throw InputError("--source2 " + second.source + ": " +
                     (second_->live() ? "a live source" : "a recording") + ", but --source " +
                     first.source + " is " + (first_->live() ? "live" : "a recording") +
                     "; a stereo pair needs two of the same kind (their times must compare)");
  }
  tolerance_s_ = tolerance_s > 0 ? tolerance_s : 0.5 / std::min(first_->fps(), second_->fps());
}

std::string FramePairSource::Describe() const {
  return first_->Describe() + " and " + second_->Describe() + ", paired within " +
         std::to_string(static_cast<int>(std::lround(1000 * tolerance_s_))) + " ms";
}

double FramePairSource::Clock(const FrameSource& source, const Frame& frame) const {
  return source.live() ? frame.arrival_wall_s : frame.time_s;
}

FrameStatus FramePairSource::Next(FramePair* pair) {
  while (true) {
    for (auto [source, pending] : {std::make_pair(first_.get(), &pending_first_),
                                   std::make_pair(second_.get(), &pending_second_)}) {
      if (*pending) continue;
      Frame frame;
      const FrameStatus status = source->Next(&frame);
      if (status != FrameStatus::kFrame) return status;
      *pending = std::move(frame);
    }
    const double t1 = Clock(*first_, *pending_first_), t2 = Clock(*second_, *pending_second_);
    if (std::abs(t1 - t2) <= tolerance_s_) {
      pair->first = std::move(*pending_first_);
      pair->second = std::move(*pending_second_);
      pair->offset_s = std::abs(t1 - t2);
      pending_first_.reset();
      pending_second_.reset();
      return FrameStatus::kFrame;
    }
    // The older frame has no partner: a newer frame of its source may.
    (t1 < t2 ? pending_first_ : pending_second_).reset();
    ++dropped_;
  }
}

}  // namespace portcal
