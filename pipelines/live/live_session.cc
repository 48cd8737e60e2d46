#include "pipelines/live/live_session.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/detection/target_pose.h"
#include "pipelines/live/frame_pair_source.h"

namespace portcal {
namespace {

double WallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

CornerMap Corners(const TargetDetection& detection) {
  CornerMap corners;
  if (!detection.found) return corners;
  for (const BoardPoint& p : detection.points) corners[static_cast<int>(p.point_id)] = p.xy;
  return corners;
}

CalibrationView ViewOf(const TargetDetection& detection, const std::string& name) {
  CalibrationView view;
  view.image_name = name;
  for (const BoardPoint& p : detection.points) {
    view.points_in_target.push_back(p.point_in_target);
    view.pixels.push_back(p.xy);
  }
  return view;
}

// 160 px wide per camera, a rig's side by side.
cv::Mat Thumbnail(const std::vector<cv::Mat>& images) {
  std::vector<cv::Mat> parts;
  for (const cv::Mat& image : images) {
    cv::Mat small;
    cv::resize(image, small, cv::Size(160, std::max(1, 160 * image.rows / std::max(1, image.cols))),
               0, 0, cv::INTER_AREA);
    if (small.channels() == 1) cv::cvtColor(small, small, cv::COLOR_GRAY2BGR);
    if (!parts.empty() && small.rows != parts[0].rows)
      cv::resize(small, small, cv::Size(160, parts[0].rows));
    parts.push_back(small);
  }
  cv::Mat joined;
  cv::hconcat(parts, joined);
  return joined;
}

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

}  // namespace

void LiveSessionOptions::Check() const {
  source.Check();
  detector.Check();
  hands_free.Check();
  estimator.guidance.Check();
  goal.Check();
  if (max_views < 0) throw OptionError("--Live.max_views", max_views, ">= 0");
  if (!(pair_tolerance_s >= 0)) {
    throw OptionError("--Live.pair_tolerance", pair_tolerance_s,
                      ">= 0 s (0: the frames' own order)");
  }
  if (Stereo() && source2 == source.source)
    throw OptionError("--source2", source2, "a source other than --source");
}

struct LiveSession::Pending {
  std::future<LiveEstimate> result;
};

LiveSession::LiveSession(const LiveSessionOptions& options, KeptFrameStore* store,
                         std::vector<KeptView> existing)
    : options_(options),
      store_(store),
      target_(ShapeOfTarget(options.detector)),
      kept_(std::move(existing)) {
  options.Check();
  channels_.push_back(Channel{options.source.source,
                              options.estimator,
                              nullptr,
                              StillnessTracker(options.hands_free),
                              cv::Size(),
                              -1,
                              {},
                              {},
                              {}});
  if (options.Stereo()) {
    LiveEstimatorOptions estimator2 = options.estimator;
    estimator2.camera = options.camera2;
    estimator2.housing = options.housing2;
    channels_.push_back(Channel{options.source2,
                                estimator2,
                                nullptr,
                                StillnessTracker(options.hands_free),
                                cv::Size(),
                                -1,
                                {},
                                {},
                                {}});
  }
  snapshot_.kept = kept_;
}

LiveSession::~LiveSession() {
  if (pending_ && pending_->result.valid()) pending_->result.wait();
}

void LiveSession::Capture() { capture_requested_ = true; }
void LiveSession::Undo() { undo_requested_ = true; }
void LiveSession::Finish() { finish_requested_ = true; }
void LiveSession::CalibrateNow() { calibrate_requested_ = true; }

void LiveSession::SetFinalStatus(const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.final_status = text;
}

bool LiveSession::WaitForFrame(int64_t frames_processed, double timeout_s,
                               LiveSnapshot* snapshot) const {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool processed = frame_processed_.wait_for(
      lock, std::chrono::duration<double>(timeout_s),
      [&] { return snapshot_.frames_processed > frames_processed || ended_; });
  if (!processed || snapshot_.frames_processed <= frames_processed) return false;
  *snapshot = snapshot_;
  return true;
}
void LiveSession::Remove(const std::string& name) {
  const std::lock_guard<std::mutex> lock(mutex_);
  remove_requested_.push_back(name);
}

LiveSnapshot LiveSession::Snapshot() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void LiveSession::Note(const std::string& message, bool warning) {
  if (warning) {
    LOG(WARNING) << "live: " << message;
  } else {
    LOG(INFO) << "live: " << message;
  }
  summary_.notes.push_back({frame_time_s_, message, warning});
  const std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.message = message;
}

void LiveSession::StartEstimate() {
  if (pending_) {
    estimate_stale_ = true;
    return;
  }
  std::vector<CalibrationView> views, views2;
  for (const KeptView& kept : kept_) {
    views.push_back(kept.view);
    views2.push_back(kept.view2);
  }
  pending_ = std::make_unique<Pending>();
  const LiveEstimator* camera1 = channels_[0].estimator.get();
  const LiveEstimator* camera2 = options_.Stereo() ? channels_[1].estimator.get() : nullptr;
  pending_->result =
      std::async(std::launch::async, [camera1, camera2, views, views2, previous = estimate_] {
        return camera2 ? EstimateRig(*camera1, *camera2, views, views2, previous.get())
                       : camera1->Estimate(views, previous.get());
      });
}

void LiveSession::CollectEstimate(bool wait) {
  if (!pending_) return;
  if (!wait && pending_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
    return;
  estimate_ = std::make_shared<const LiveEstimate>(pending_->result.get());
  pending_.reset();
  std::istringstream lines(estimate_->Summary());  // a rig's: a line per camera and one for the rig
  for (std::string line; std::getline(lines, line);) LOG(INFO) << "live: estimate from " << line;
  if (estimate_->next) {
    LOG(INFO) << "live: next pose (" << estimate_->next->why << "): target centre at "
              << estimate_->next->cam_from_target.translation.transpose() << " m";
  } else if (!estimate_->suggestion_error.empty()) {
    LOG(WARNING) << "live: no suggestion: " << estimate_->suggestion_error;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.estimate = estimate_;
  }
  UpdateGoal();
  if (estimate_stale_) {
    estimate_stale_ = false;
    StartEstimate();
    if (wait) CollectEstimate(true);
  }
}

void LiveSession::UpdateGoal() {
  std::vector<CornerMap> corners1, corners2;
  for (const KeptView& kept : kept_) {
    corners1.push_back(kept.corners);
    corners2.push_back(kept.corners2);
  }
  const double target = options_.goal.target_uncertainty_px;
  LiveGoal goal = EvaluateGoal(*estimate_, corners1, channels_[0].size, target);
  if (estimate_->camera2) {
    goal =
        CombineGoals(goal, EvaluateGoal(*estimate_->camera2, corners2, channels_[1].size, target));
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.goal = goal;
  }
  if (goal.met != goal_met_) {
    goal_met_ = goal.met;
    if (goal.met || estimate_->num_views > 0) LOG(INFO) << "live: goal: " << goal.Summary();
  }
}

double LiveSession::Gain(const std::vector<CalibrationView>& views) const {
  if (views.size() == 1) return channels_[0].estimator->Gain(*estimate_, views[0]);
  return RigGain(*channels_[0].estimator, *channels_[1].estimator, *estimate_, views[0], views[1]);
}

bool LiveSession::TryKeep(const std::vector<Sight>& sights, bool requested) {
  if (!requested) {
    const std::string repeat = NotNovel(sights);
    if (repeat == "refused before") return false;
    if (!repeat.empty()) {
      Note("held still, not kept: " + repeat + "; move the target (see the suggestion)", false);
      return false;
    }
  }
  TargetDetectorOptions precise = options_.detector;
  precise.precise_fit = true;
  std::vector<TargetDetection> detections;
  std::vector<CalibrationView> views;
  std::vector<cv::Mat> images;
  for (size_t c = 0; c < sights.size(); ++c) {
    detections.push_back(DetectTarget(sights[c].gray, precise));
    if (!detections.back().found) {
      const std::string camera = sights.size() > 1 ? " of camera " + std::to_string(c + 1) : "";
      Note("held still, frame " + std::to_string(sights[c].frame->index) + camera +
               " not kept: the precise fit failed (" + detections.back().reason + ")",
           true);
      RememberRefused(sights);
      return false;
    }
    views.push_back(ViewOf(detections.back(), ""));
    images.push_back(sights[c].frame->image);
  }
  if (!requested && estimate_) {
    const double gain = Gain(views);
    if (gain < options_.hands_free.min_gain) {
      std::ostringstream text;
      text << "held still, not kept: this view would lower the uncertainty by only "
           << std::setprecision(2) << 100 * gain << " % (--Live.min_gain "
           << 100 * options_.hands_free.min_gain << " %); move the target (see the suggestion)";
      Note(text.str(), false);
      RememberRefused(sights);
      return false;
    }
  }
  std::string name;
  try {
    name = store_->Store(images, detections);
  } catch (const InputError& e) {
    Note(std::string("frame not stored: ") + e.what(), true);
    return false;
  } catch (const DatabaseError& e) {
    Note(std::string("frame not stored (it can be captured again): ") + e.what(), true);
    return false;
  }
  KeptView kept{
      name, sights[0].frame->time_s, views[0], Corners(detections[0]), Thumbnail(images), {}, {}};
  kept.view.image_name = name;
  if (sights.size() > 1) {
    kept.view2 = views[1];
    kept.view2.image_name = name;
    kept.corners2 = Corners(detections[1]);
  }
  kept_.push_back(kept);
  rejected_.clear();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.kept = kept_;
  }
  Note("kept " + name + " (frame " + std::to_string(sights[0].frame->index) + ", " +
           std::to_string(detections[0].points.size()) + " corners)" +
           (requested ? ", on request" : ""),
       false);
  StartEstimate();
  return true;
}

void LiveSession::Process(std::vector<Sight>& sights, double arrival_wall_s) {
  TargetDetectorOptions quick = options_.detector;
  quick.precise_fit = false;
  // A rig's second image on the other core.
  std::future<TargetDetection> second;
  if (sights.size() > 1) {
    second = std::async(std::launch::async,
                        [&quick, gray = sights[1].gray] { return DetectTarget(gray, quick); });
  }
  const TargetDetection detection = DetectTarget(sights[0].gray, quick);
  bool seen = detection.found;
  sights[0].corners = Corners(detection);
  if (second.valid()) {
    const TargetDetection detection2 = second.get();
    seen = seen && detection2.found;
    sights[1].corners = Corners(detection2);
  }
  const double time_s = sights[0].frame->time_s;
  frame_time_s_ = time_s;
  const StillnessTracker::State hold =
      Hold(sights, time_s, detection.found ? "" : detection.reason);
  std::optional<PoseDistance> to_suggestion;
  if (detection.found && estimate_ && estimate_->next) {
    if (const auto pose = EstimateTargetPose(detection, estimate_->camera)) {
      const LiveEstimator& estimator = *channels_[0].estimator;
      to_suggestion =
          DistanceToSuggestion(estimator.Unknowns(estimate_->camera), estimator.target(),
                               pose->cam_from_target, estimate_->next->cam_from_target);
    }
  }
  ++summary_.frames;
  summary_.frames_with_target += seen;
  const bool requested = seen && capture_requested_.exchange(false);
  if (requested) {
    TryKeep(sights, true);
  } else if (options_.hands_free.enabled && seen && hold.still && !spell_tried_) {
    spell_tried_ = true;  // once per still spell, kept or refused with its reason
    TryKeep(SharpestSights(), false);
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  // Frames processed per second, over about the last second.
  if (snapshot_.arrival_wall_s > 0 && arrival_wall_s > snapshot_.arrival_wall_s) {
    const double rate = 1 / (arrival_wall_s - snapshot_.arrival_wall_s);
    const double weight = std::min(1.0, (arrival_wall_s - snapshot_.arrival_wall_s) / 1.0);
    snapshot_.fps = snapshot_.fps > 0 ? (1 - weight) * snapshot_.fps + weight * rate : rate;
  }
  snapshot_.frame = sights[0].gray;
  snapshot_.arrival_wall_s = arrival_wall_s;
  ++snapshot_.frames_processed;
  snapshot_.time_s = time_s;
  snapshot_.frame_index = sights[0].frame->index;
  snapshot_.target_seen = seen;
  snapshot_.corners = sights[0].corners;
  if (sights.size() > 1) {
    snapshot_.frame2 = sights[1].gray;
    snapshot_.corners2 = sights[1].corners;
  }
  snapshot_.hold = hold;
  snapshot_.to_suggestion = to_suggestion;
  frame_processed_.notify_all();
}

void LiveSession::ApplyRequests() {
  std::vector<std::string> names;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    names.swap(remove_requested_);
  }
  if (undo_requested_.exchange(false) && !kept_.empty()) names.push_back(kept_.back().name);
  if (names.empty()) return;
  bool changed = false;
  for (const std::string& name : names) {
    const auto it =
        std::find_if(kept_.begin(), kept_.end(), [&](const KeptView& k) { return k.name == name; });
    if (it == kept_.end()) continue;
    try {
      store_->Remove(name);
    } catch (const InputError& e) {
      Note("cannot remove " + name + ": " + e.what(), true);
      continue;
    }
    kept_.erase(it);
    changed = true;
    Note("removed " + name, false);
  }
  if (!changed) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.kept = kept_;
  }
  StartEstimate();
}

void LiveSession::PrintStatus(double time_s) {
  const double now = WallSeconds();
  if (options_.status_interval_s <= 0 || now - last_status_s_ < options_.status_interval_s) return;
  last_status_s_ = now;
  const LiveSnapshot s = Snapshot();
  const double fps = s.fps;
  std::ostringstream line;
  line << std::fixed << std::setprecision(1) << "live: t " << time_s << " s, " << fps << " fps; ";
  if (s.target_seen) {
    line << "target seen (" << s.corners.size() << " corners), held " << s.hold.held_s << " s";
  } else {
    line << "no target";
  }
  line << "; " << kept_.size() << " kept";
  if (s.goal.determined) {
    line << "; goal "
         << (s.goal.met ? "met" : std::to_string(static_cast<int>(100 * s.goal.progress)) + " %");
  }
  if (estimate_ && estimate_->next) {
    line << "; next: " << estimate_->next->why;
    if (s.to_suggestion)
      line << ", " << std::setprecision(0) << s.to_suggestion->outline_px << " px away";
  }
  LOG(INFO) << line.str();
}

bool LiveSession::CheckSize(Channel* channel, const cv::Mat& gray, const Frame& frame) {
  if (channel->size.area() == 0) {
    channel->size = gray.size();
    LiveEstimatorOptions& estimator = channel->estimator_options;
    if (estimator.camera.width == 0) {
      estimator.camera = Camera::FromModelName(
          estimator.camera.ModelName(), 1.2 * std::max(gray.cols, gray.rows), gray.cols, gray.rows);
    } else if (static_cast<int>(estimator.camera.width) != gray.cols ||
               static_cast<int>(estimator.camera.height) != gray.rows) {
      throw InputError(channel->source + ": frames are " + std::to_string(gray.cols) + "x" +
                       std::to_string(gray.rows) + ", the camera (--input_calibration) is " +
                       std::to_string(estimator.camera.width) + "x" +
                       std::to_string(estimator.camera.height));
    }
    channel->estimator = std::make_unique<LiveEstimator>(estimator, target_);
    // The opening suggestion (or the continued session's estimate), once
    // every camera is sized.
    if (std::all_of(channels_.begin(), channels_.end(),
                    [](const Channel& c) { return c.estimator != nullptr; })) {
      StartEstimate();
    }
    return true;
  }
  if (gray.size() == channel->size) {
    channel->other_size_since_s = -1;
    return true;
  }
  const std::string sizes = std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                            " instead of " + std::to_string(channel->size.width) + "x" +
                            std::to_string(channel->size.height);
  // In the source's time, not the wall's: a recorded file read as fast as
  // it decodes (--Live.realtime 0) spends seconds of video in a fraction of
  // one, and a resolution that changed for good must fail there too.
  if (channel->other_size_since_s < 0) {
    channel->other_size_since_s = frame.time_s;
    Note(channel->source + ": frame " + std::to_string(frame.index) + " is " + sizes + "; skipped",
         true);
  } else if (frame.time_s - channel->other_size_since_s > options_.source.stall_seconds) {
    throw InputError(channel->source + ": the frames changed size to " + sizes + " for " +
                     std::to_string(static_cast<int>(options_.source.stall_seconds)) +
                     " s (a stream's resolution changed?)");
  }
  return false;
}

// One camera's frames, or a rig's paired by time.
class LiveSession::Frames {
 public:
  explicit Frames(const LiveSessionOptions& options) : realtime_(options.source.realtime) {
    if (!options.Stereo()) {
      single_ = std::make_unique<FrameSource>(options.source);
      return;
    }
    FrameSourceOptions second = options.source;
    second.source = options.source2;
    pairs_ = std::make_unique<FramePairSource>(options.source, second, options.pair_tolerance_s);
  }
  FrameStatus Next(FramePair* pair) {
    return pairs_ ? pairs_->Next(pair) : single_->Next(&pair->first);
  }
  std::string Describe() const { return pairs_ ? pairs_->Describe() : single_->Describe(); }
  // A recorded source read as fast as it decodes: nothing waits on the
  // wall, so the session waits for each estimate and its result is the same
  // on a loaded machine as on an idle one.
  bool Replay() const {
    const FrameSource& first = pairs_ ? pairs_->first() : *single_;
    return !realtime_ && !first.live();
  }

 private:
  bool realtime_ = true;
  std::unique_ptr<FrameSource> single_;
  std::unique_ptr<FramePairSource> pairs_;
};

// The loop's reasons to stop before the next frame ("" to go on).
std::string LiveSession::StopReason() const {
  if (CancelFlag::Requested()) return "interrupted";
  if (finish_requested_) return "finish requested";
  if (options_.goal.auto_finish && goal_met_ && !pending_ && !estimate_stale_) {
    return "the goal was met (--Live.auto_finish)";
  }
  if (options_.max_views > 0 && static_cast<int>(kept_.size()) >= options_.max_views) {
    return std::to_string(options_.max_views) + " views kept (--Live.max_views)";
  }
  return "";
}

LiveSummary LiveSession::Run() {
  Frames source(options_);
  LOG(INFO) << "live: reading " << source.Describe();
  const double start = WallSeconds();
  int stalls = 0;
  FramePair frames;
  while (true) {
    summary_.end_reason = StopReason();
    if (!summary_.end_reason.empty()) break;
    const FrameStatus status = source.Next(&frames);
    if (status == FrameStatus::kEnd) {
      summary_.end_reason = "the source ended";
      break;
    }
    if (status == FrameStatus::kStalled) {
      Note(source.Describe() + ": no frame for " +
               std::to_string(static_cast<int>(options_.source.stall_seconds)) + " s (stalled?)",
           true);
      if (++stalls >= 3) {
        summary_.end_reason = "the source stalled";
        break;
      }
      continue;
    }
    stalls = 0;
    const double arrival = WallSeconds();
    // Every camera's frame, each of its camera's size (else none is processed).
    std::vector<Sight> sights;
    for (const Frame* frame : {&frames.first, &frames.second}) {
      if (sights.size() == channels_.size() || frame->image.empty()) break;
      const cv::Mat gray = Gray(frame->image);
      if (!CheckSize(&channels_[sights.size()], gray, *frame)) break;
      sights.push_back({frame, gray, {}});
    }
    if (sights.size() != channels_.size()) continue;
    Process(sights, arrival);
    if (calibrate_requested_.exchange(false)) StartEstimate();
    ApplyRequests();
    CollectEstimate(source.Replay());
    PrintStatus(frames.first.time_s);
  }
  CollectEstimate(true);
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ended_ = true;
    frame_processed_.notify_all();
  }
  summary_.kept = static_cast<int>(kept_.size());
  summary_.kept_views = kept_;
  summary_.seconds = WallSeconds() - start;
  summary_.estimate = estimate_;
  LOG(INFO) << "live: " << summary_.end_reason << "; " << summary_.frames << " frames in "
            << std::fixed << std::setprecision(1) << summary_.seconds << " s, target in "
            << summary_.frames_with_target << ", " << summary_.kept << " views kept";
  return summary_;
}

}  // namespace portcal
