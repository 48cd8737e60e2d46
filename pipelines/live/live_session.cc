#include "pipelines/live/live_session.h"

#include <chrono>
#include <future>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/detection/target_pose.h"

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

cv::Mat Thumbnail(const cv::Mat& image) {
  cv::Mat small;
  cv::resize(image, small, cv::Size(160, std::max(1, 160 * image.rows / std::max(1, image.cols))), 0, 0,
             cv::INTER_AREA);
  if (small.channels() == 1) cv::cvtColor(small, small, cv::COLOR_GRAY2BGR);
  return small;
}

cv::Mat Gray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

}  // namespace

TargetShape ShapeOfTarget(const TargetDetectorOptions& detector) {
  std::vector<Eigen::Vector3d> points;
  for (const BoardPoint& p : TargetLayout(detector)) points.push_back(p.point_in_target);
  return TargetShape::FromPoints(points);
}

void LiveSessionOptions::Check() const {
  source.Check();
  detector.Check();
  hands_free.Check();
  estimator.guidance.Check();
  if (max_views < 0) throw OptionError("--Live.max_views", std::to_string(max_views), ">= 0");
}

struct LiveSession::Pending {
  std::future<LiveEstimate> result;
};

LiveSession::LiveSession(const LiveSessionOptions& options, KeptFrameStore* store, std::vector<KeptView> existing)
    : options_(options), store_(store), tracker_(options.hands_free), target_(ShapeOfTarget(options.detector)),
      kept_(std::move(existing)) {
  options.Check();
  snapshot_.kept = kept_;
}

LiveSession::~LiveSession() {
  if (pending_ && pending_->result.valid()) pending_->result.wait();
}

void LiveSession::Capture() { capture_requested_ = true; }
void LiveSession::Undo() { undo_requested_ = true; }
void LiveSession::Finish() { finish_requested_ = true; }
void LiveSession::CalibrateNow() { calibrate_requested_ = true; }

bool LiveSession::WaitForFrame(int64_t frames_processed, double timeout_s, LiveSnapshot* snapshot) const {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool processed = frame_processed_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
    return snapshot_.frames_processed > frames_processed || ended_;
  });
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
  const std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.message = message;
}

void LiveSession::StartEstimate() {
  if (pending_) {
    estimate_stale_ = true;
    return;
  }
  std::vector<CalibrationView> views;
  for (const KeptView& kept : kept_) views.push_back(kept.view);
  pending_ = std::make_unique<Pending>();
  pending_->result = std::async(std::launch::async, [estimator = estimator_.get(), views, previous = estimate_] {
    return estimator->Estimate(views, previous.get());
  });
}

void LiveSession::CollectEstimate(bool wait) {
  if (!pending_) return;
  if (!wait && pending_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  estimate_ = std::make_shared<const LiveEstimate>(pending_->result.get());
  pending_.reset();
  LOG(INFO) << "live: estimate from " << estimate_->Summary();
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
  if (estimate_stale_) {
    estimate_stale_ = false;
    StartEstimate();
    if (wait) CollectEstimate(true);
  }
}

void LiveSession::RememberRefused(const CornerMap& corners) {
  KeptView refused;  // seen: the same still spell is not fitted again
  refused.corners = corners;
  rejected_.push_back(refused);
}

bool LiveSession::TryKeep(const Frame& frame, const cv::Mat& gray, const CornerMap& corners, bool requested) {
  const cv::Mat& image = frame.image;
  const double novelty_px =
      options_.hands_free.novelty_fraction * std::hypot(static_cast<double>(image.cols), static_cast<double>(image.rows));
  if (!requested) {
    for (const std::vector<KeptView>* seen : {&kept_, &rejected_}) {
      for (const KeptView& kept : *seen) {
        if (MeanCornerShift(corners, kept.corners) < novelty_px) return false;  // the same view again
      }
    }
  }
  TargetDetectorOptions precise = options_.detector;
  precise.precise_fit = true;
  const TargetDetection detection = DetectTarget(gray, precise);
  if (!detection.found) {
    Note("frame " + std::to_string(frame.index) + " not kept: the precise fit failed (" + detection.reason + ")", true);
    RememberRefused(corners);
    return false;
  }
  const CalibrationView view = ViewOf(detection, "");
  if (!requested && estimate_) {
    const double gain = estimator_->Gain(*estimate_, view);
    if (gain < options_.hands_free.min_gain) {
      std::ostringstream text;
      text << "held still, but this view would lower the uncertainty by only " << std::setprecision(2)
           << 100 * gain << " %: move the target (see the suggestion)";
      Note(text.str(), false);
      RememberRefused(corners);
      return false;
    }
  }
  std::string name;
  try {
    name = store_->Store(image, detection);
  } catch (const InputError& e) {
    Note(std::string("frame not stored: ") + e.what(), true);
    return false;
  } catch (const DatabaseError& e) {
    Note(std::string("frame not stored (it can be captured again): ") + e.what(), true);
    return false;
  }
  KeptView kept{name, frame.time_s, view, Corners(detection), Thumbnail(image)};
  kept.view.image_name = name;
  kept_.push_back(kept);
  rejected_.clear();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.kept = kept_;
  }
  Note("kept " + name + " (frame " + std::to_string(frame.index) + ", " + std::to_string(detection.points.size()) +
           " corners)" + (requested ? ", on request" : ""),
       false);
  StartEstimate();
  return true;
}

void LiveSession::Process(const Frame& frame, const cv::Mat& gray, double arrival_wall_s) {
  TargetDetectorOptions quick = options_.detector;
  quick.precise_fit = false;
  const TargetDetection detection = DetectTarget(gray, quick);
  const CornerMap corners = Corners(detection);
  const StillnessTracker::State hold = tracker_.Update(frame.time_s, corners, CornerSharpness(gray, corners));
  std::optional<PoseDistance> to_suggestion;
  if (detection.found && estimate_ && estimate_->next) {
    if (const auto pose = EstimateTargetPose(detection, estimate_->camera)) {
      to_suggestion = DistanceToSuggestion(estimator_->Unknowns(estimate_->camera), estimator_->target(),
                                           pose->cam_from_target, estimate_->next->cam_from_target);
    }
  }
  ++summary_.frames;
  summary_.frames_with_target += detection.found;
  const bool requested = detection.found && capture_requested_.exchange(false);
  if (requested || (options_.hands_free.enabled && hold.still && hold.sharp)) {
    if (TryKeep(frame, gray, corners, requested)) tracker_.Reset();
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  // Frames processed per second, over about the last second.
  if (snapshot_.arrival_wall_s > 0 && arrival_wall_s > snapshot_.arrival_wall_s) {
    const double rate = 1 / (arrival_wall_s - snapshot_.arrival_wall_s);
    const double weight = std::min(1.0, (arrival_wall_s - snapshot_.arrival_wall_s) / 1.0);
    snapshot_.fps = snapshot_.fps > 0 ? (1 - weight) * snapshot_.fps + weight * rate : rate;
  }
  snapshot_.frame = gray;
  snapshot_.arrival_wall_s = arrival_wall_s;
  ++snapshot_.frames_processed;
  snapshot_.time_s = frame.time_s;
  snapshot_.frame_index = frame.index;
  snapshot_.target_seen = detection.found;
  snapshot_.corners = corners;
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
    const auto it = std::find_if(kept_.begin(), kept_.end(), [&](const KeptView& k) { return k.name == name; });
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
  if (estimate_ && estimate_->next) {
    line << "; next: " << estimate_->next->why;
    if (s.to_suggestion) line << ", " << std::setprecision(0) << s.to_suggestion->outline_px << " px away";
  }
  LOG(INFO) << line.str();
}

bool LiveSession::CheckSize(const cv::Mat& gray, int64_t index) {
  if (size_.area() == 0) {
    size_ = gray.size();
    LiveEstimatorOptions& estimator = options_.estimator;
    if (estimator.camera.width == 0) {
      estimator.camera = Camera::FromModelName(estimator.camera.ModelName(), 1.2 * std::max(gray.cols, gray.rows),
                                               gray.cols, gray.rows);
    } else if (static_cast<int>(estimator.camera.width) != gray.cols ||
               static_cast<int>(estimator.camera.height) != gray.rows) {
      throw InputError(options_.source.source + ": frames are " + std::to_string(gray.cols) + "x" +
                       std::to_string(gray.rows) + ", the camera (--input_calibration) is " +
                       std::to_string(estimator.camera.width) + "x" + std::to_string(estimator.camera.height));
    }
    estimator_ = std::make_unique<LiveEstimator>(estimator, target_);
    StartEstimate();  // the opening suggestion (or the continued session's estimate)
    return true;
  }
  if (gray.size() == size_) {
    other_size_since_s_ = -1;
    return true;
  }
  const std::string sizes = std::to_string(gray.cols) + "x" + std::to_string(gray.rows) + " instead of " +
                            std::to_string(size_.width) + "x" + std::to_string(size_.height);
  if (other_size_since_s_ < 0) {
    other_size_since_s_ = WallSeconds();
    Note(options_.source.source + ": frame " + std::to_string(index) + " is " + sizes + "; skipped", true);
  } else if (WallSeconds() - other_size_since_s_ > options_.source.stall_seconds) {
    throw InputError(options_.source.source + ": the frames changed size to " + sizes + " for " +
                     std::to_string(static_cast<int>(options_.source.stall_seconds)) +
                     " s (a stream's resolution changed?)");
  }
  return false;
}

LiveSummary LiveSession::Run() {
  FrameSource source(options_.source);
  LOG(INFO) << "live: reading " << source.Describe();
  const double start = WallSeconds();
  int stalls = 0;
  Frame frame;
  while (true) {
    if (CancelFlag::Requested()) {
      summary_.end_reason = "interrupted";
      break;
    }
    if (finish_requested_) {
      summary_.end_reason = "finish requested";
      break;
    }
    if (options_.max_views > 0 && static_cast<int>(kept_.size()) >= options_.max_views) {
      summary_.end_reason = std::to_string(options_.max_views) + " views kept (--Live.max_views)";
      break;
    }
    const FrameStatus status = source.Next(&frame);
    if (status == FrameStatus::kEnd) {
      summary_.end_reason = "the source ended";
      break;
    }
    if (status == FrameStatus::kStalled) {
      Note(source.Describe() + ": no frame for " + std::to_string(static_cast<int>(options_.source.stall_seconds)) +
               " s (stalled?)",
           true);
      if (++stalls >= 3) {
        summary_.end_reason = "the source stalled";
        break;
      }
      continue;
    }
    stalls = 0;
    if (frame.image.empty()) continue;
    const double arrival = WallSeconds();
    const cv::Mat gray = Gray(frame.image);
    if (!CheckSize(gray, frame.index)) continue;
    Process(frame, gray, arrival);
    if (calibrate_requested_.exchange(false)) StartEstimate();
    ApplyRequests();
    CollectEstimate(false);
    PrintStatus(frame.time_s);
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
  LOG(INFO) << "live: " << summary_.end_reason << "; " << summary_.frames << " frames in " << std::fixed
            << std::setprecision(1) << summary_.seconds << " s, target in " << summary_.frames_with_target << ", "
            << summary_.kept << " views kept";
  return summary_;
}

}  // namespace portcal
