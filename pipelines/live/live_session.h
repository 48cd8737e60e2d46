// A live calibration: frames from a source, the target found quickly in
// each, kept hands-free (or on request), each kept frame fitted precisely
// and stored, the estimate and the next suggested pose recomputed on a
// worker thread after each keep so that frames keep flowing.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pipelines/detection/target_detector.h"
#include "pipelines/live/frame_source.h"
#include "pipelines/live/hands_free.h"
#include "pipelines/live/live_estimator.h"

namespace portcal {

// Where kept frames go (an image file and database rows: the stage's
// business). Store throws to refuse a frame; the session goes on.
class KeptFrameStore {
 public:
  virtual ~KeptFrameStore() = default;
  // Returns the image's name.
  virtual std::string Store(const cv::Mat& image, const TargetDetection& detection) = 0;
  virtual void Remove(const std::string& name) = 0;
};

struct LiveSessionOptions {
  FrameSourceOptions source;
  TargetDetectorOptions detector;  // its precise_fit is set per use
  HandsFreeOptions hands_free;
  LiveEstimatorOptions estimator;
  int max_views = 0;              // finish after this many kept views (0: when the source ends)
  double status_interval_s = 2;   // a status line on stderr this often (<= 0: never)
  void Check() const;             // throws OptionError naming the option
};

// The target as guidance sees it: every point the detector options'
// target has.
TargetShape ShapeOfTarget(const TargetDetectorOptions& detector);

// One kept view as the session holds it.
struct KeptView {
  std::string name;
  double time_s = 0;
  CalibrationView view;  // the precise corners
  CornerMap corners;
  cv::Mat thumbnail;     // BGR, 160 px wide (empty for a continued session's views)
};

// What a viewer shows (a copy, taken under the session's lock).
struct LiveSnapshot {
  cv::Mat frame;             // the newest frame, gray
  double time_s = 0;
  int64_t frame_index = 0;
  int64_t frames_processed = 0;  // counts every processed frame (WaitForFrame)
  double arrival_wall_s = 0;     // when the frame was read (steady clock, s)
  double fps = 0;            // frames processed per second, recently
  bool target_seen = false;
  CornerMap corners;         // quick corners of the newest frame
  StillnessTracker::State hold;
  std::vector<KeptView> kept;
  std::shared_ptr<const LiveEstimate> estimate;
  std::optional<PoseDistance> to_suggestion;  // the current pose vs the suggestion
  std::string message;       // the last warning or event, for the page
};

struct LiveSummary {
  int64_t frames = 0;             // processed
  int64_t frames_with_target = 0;
  int kept = 0;
  double seconds = 0;
  std::string end_reason;         // "the source ended", "finish requested", ...
  std::vector<KeptView> kept_views;  // in the order kept
  std::shared_ptr<const LiveEstimate> estimate;
};

class LiveSession {
 public:
  // `existing`: views already kept in this database (a continued session).
  LiveSession(const LiveSessionOptions& options, KeptFrameStore* store, std::vector<KeptView> existing = {});
  ~LiveSession();

  // Until the source ends, max_views are kept, Finish() or Ctrl-C
  // (CancelFlag). Throws InputError for a source that cannot be opened or
  // frames that change size for good; what was kept stays kept.
  LiveSummary Run();

  // From a viewer, any thread: keep the next frame where the target is
  // seen; drop the last or a named kept view; finish.
  void Capture();
  void Undo();
  void Remove(const std::string& name);
  void Finish();
  // Solve the kept views now (the estimate is also updated after each keep).
  void CalibrateNow();
  LiveSnapshot Snapshot() const;
  // Waits until a frame after `frames_processed` is processed (or
  // `timeout_s` passes); false on time-out or once the session has ended.
  bool WaitForFrame(int64_t frames_processed, double timeout_s, LiveSnapshot* snapshot) const;
  // The target as guidance sees it (its points and outline).
  const TargetShape& target() const { return target_; }

 private:
  void Process(const Frame& frame, const cv::Mat& gray, double arrival_wall_s);
  // The first frame fixes the image size (and the camera's, if unknown);
  // false for a frame of another size.
  bool CheckSize(const cv::Mat& gray, int64_t index);
  bool TryKeep(const Frame& frame, const cv::Mat& gray, const CornerMap& corners, bool requested);
  // A still view refused (no precise fit, too little gain): not tried
  // again until a view is kept.
  void RememberRefused(const CornerMap& corners);
  void ApplyRequests();
  void StartEstimate();
  void CollectEstimate(bool wait);
  void PrintStatus(double time_s);
  void Note(const std::string& message, bool warning);

  LiveSessionOptions options_;
  KeptFrameStore* store_;
  std::unique_ptr<LiveEstimator> estimator_;
  StillnessTracker tracker_;
  mutable std::mutex mutex_;
  mutable std::condition_variable frame_processed_;
  bool ended_ = false;
  TargetShape target_;
  std::atomic<bool> calibrate_requested_{false};
  LiveSnapshot snapshot_;
  std::vector<KeptView> kept_;
  std::vector<KeptView> rejected_;  // held still but refused since the last keep
  std::shared_ptr<const LiveEstimate> estimate_;
  std::atomic<bool> capture_requested_{false};
  std::atomic<bool> undo_requested_{false};
  std::atomic<bool> finish_requested_{false};
  std::vector<std::string> remove_requested_;
  struct Pending;
  std::unique_ptr<Pending> pending_;  // the estimate being computed
  bool estimate_stale_ = false;       // views changed while it ran
  double last_status_s_ = -1e9;
  cv::Size size_;
  double other_size_since_s_ = -1;  // wall time frames of another size began
  LiveSummary summary_;
};

}  // namespace portcal
