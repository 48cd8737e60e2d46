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
#include <stdexcept>
#include <string>
#include <vector>

#include "pipelines/detection/target_detector.h"
#include "pipelines/guidance/live_estimator.h"
#include "pipelines/live/frame_source.h"
#include "pipelines/live/hands_free.h"
#include "pipelines/live/live_goal.h"

namespace portcal {

// Where kept frames go (an image file and database rows: the stage's
// business). Store throws InputError or DatabaseError to refuse a frame;
// the session goes on. It throws FrameStoreBroken where no frame can be
// kept any more (a full disk, a folder that became read-only): the session
// ends with that error, and the views kept before stay where they are
// (a calibration of fewer views than the user held would look complete).
class FrameStoreBroken : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class KeptFrameStore {
 public:
  virtual ~KeptFrameStore() = default;
  // One image per camera (a rig's pair, in camera order) with its target;
  // returns the view's name (a pair's: the name its two images share).
  virtual std::string Store(const std::vector<cv::Mat>& images,
                            const std::vector<TargetDetection>& detections) = 0;
  virtual void Remove(const std::string& name) = 0;
};

struct LiveSessionOptions {
  FrameSourceOptions source;
  TargetDetectorOptions detector;  // its precise_fit is set per use
  HandsFreeOptions hands_free;
  LiveEstimatorOptions estimator;
  LiveGoalOptions goal;
  int max_views = 0;             // finish after this many kept views (0: when the source ends)
  double status_interval_s = 2;  // a status line on stderr this often (<= 0: never)
  // A stereo rig: camera 2's source (empty: one camera; the other source
  // options are shared), frames paired by time within pair_tolerance_s
  // (<= 0: half a frame interval), and camera 2's start (its model, or its
  // in-air intrinsics and housing; the rest as `estimator`).
  std::string source2;
  double pair_tolerance_s = 0;
  Camera camera2;
  std::optional<Housing> housing2;
  bool Stereo() const { return !source2.empty(); }
  void Check() const;  // throws OptionError naming the option
};

// One kept view as the session holds it.
struct KeptView {
  std::string name;
  double time_s = 0;
  CalibrationView view;  // the precise corners
  CornerMap corners;
  cv::Mat thumbnail;  // BGR, 160 px wide (empty for a continued session's views)
  // A rig's camera 2 (empty for one camera).
  CalibrationView view2;
  CornerMap corners2;
};

// What a viewer shows (a copy, taken under the session's lock).
struct LiveSnapshot {
  cv::Mat frame;  // the newest frame, gray
  double time_s = 0;
  int64_t frame_index = 0;
  int64_t frames_processed = 0;  // counts every processed frame (WaitForFrame)
  double arrival_wall_s = 0;     // when the frame was read (steady clock, s)
  double fps = 0;                // frames processed per second, recently
  bool target_seen = false;      // by every camera
  CornerMap corners;             // quick corners of the newest frame
  cv::Mat frame2;                // a rig's camera 2 (empty for one camera)
  CornerMap corners2;
  StillnessTracker::State hold;
  std::vector<KeptView> kept;
  std::shared_ptr<const LiveEstimate> estimate;
  std::optional<PoseDistance> to_suggestion;  // the current pose vs the suggestion
  LiveGoal goal;                              // of the newest estimate
  std::string message;                        // the last warning or event, for the page
  std::string
      final_status;  // after the session: the final calibration's progress, then its outcome
};

// What the session said (kept, refused and why), at a frame's media time.
struct LiveNote {
  double time_s = 0;
  std::string text;
  bool warning = false;
};

struct LiveSummary {
  int64_t frames = 0;  // processed
  int64_t frames_with_target = 0;
  int kept = 0;
  double seconds = 0;
  std::string end_reason;            // "the source ended", "finish requested", ...
  std::vector<KeptView> kept_views;  // in the order kept
  std::vector<LiveNote> notes;       // in the order said
  std::shared_ptr<const LiveEstimate> estimate;
};

class LiveSession {
 public:
  // `existing`: views already kept in this database (a continued session).
  LiveSession(const LiveSessionOptions& options, KeptFrameStore* store,
              std::vector<KeptView> existing = {});
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
  // After Run: what the final calibration is doing or gave, for viewers.
  void SetFinalStatus(const std::string& text);
  LiveSnapshot Snapshot() const;
  // Waits until a frame after `frames_processed` is processed (or
  // `timeout_s` passes); false on time-out or once the session has ended.
  bool WaitForFrame(int64_t frames_processed, double timeout_s, LiveSnapshot* snapshot) const;
  // The target as guidance sees it (its points and outline).
  const TargetShape& target() const { return target_; }

 private:
  // What each camera saw at one moment (one or two).
  struct Sight {
    const Frame* frame;
    cv::Mat gray;
    CornerMap corners;
  };
  // Per camera: its estimator, its stillness, its image size, the still
  // spell's sharpest frame (what a hands-free keep stores).
  struct Channel {
    std::string source;
    LiveEstimatorOptions estimator_options;
    std::unique_ptr<LiveEstimator> estimator;
    StillnessTracker tracker;
    cv::Size size;
    double other_size_since_s =
        -1;  // the source's time (Frame::time_s) frames of another size began
    Frame sharpest;
    cv::Mat sharpest_gray;
    CornerMap sharpest_corners;
  };

  void Process(std::vector<Sight>& sights, double arrival_wall_s);
  // The first frame fixes the image size (and the camera's, if unknown);
  // false for a frame of another size.
  bool CheckSize(Channel* channel, const cv::Mat& gray, const Frame& frame);
  // "" when the view is new, else why not (the kept view it repeats).
  std::string NotNovel(const std::vector<Sight>& sights) const;
  // Hands-free: the spells' states combined; the sharpest frames kept;
  // a pose held and not kept, said.
  StillnessTracker::State Hold(const std::vector<Sight>& sights, double time_s,
                               const std::string& lost_reason);
  std::vector<Sight> SharpestSights() const;
  bool TryKeep(const std::vector<Sight>& sights, bool requested);
  double Gain(const std::vector<CalibrationView>& views) const;
  // A still view refused (no precise fit, too little gain): not tried
  // again until a view is kept.
  void RememberRefused(const std::vector<Sight>& sights);
  std::string StopReason() const;
  class Frames;
  void ApplyRequests();
  void StartEstimate();
  void CollectEstimate(bool wait);
  void PrintStatus(double time_s);
  void Note(const std::string& message, bool warning);
  void UpdateGoal();

  LiveSessionOptions options_;
  KeptFrameStore* store_;
  std::vector<Channel> channels_;  // camera 1 (and a rig's camera 2)
  mutable std::mutex mutex_;
  mutable std::condition_variable frame_processed_;
  bool ended_ = false;
  TargetShape target_;
  std::atomic<bool> calibrate_requested_{false};
  LiveSnapshot snapshot_;
  std::vector<KeptView> kept_;
  std::vector<KeptView> rejected_;  // held still but refused since the last keep
  bool spell_tried_ = false;        // the still spell was tried: not again
  std::shared_ptr<const LiveEstimate> estimate_;
  std::atomic<bool> capture_requested_{false};
  std::atomic<bool> undo_requested_{false};
  std::atomic<bool> finish_requested_{false};
  bool goal_met_ = false;  // by the newest estimate (said once when it changes)
  std::vector<std::string> remove_requested_;
  struct Pending;
  std::unique_ptr<Pending> pending_;  // the estimate being computed
  bool estimate_stale_ = false;       // views changed while it ran
  double last_status_s_ = -1e9;
  double frame_time_s_ = 0;  // the frame being processed (the notes' time)
  LiveSummary summary_;
};

}  // namespace portcal
