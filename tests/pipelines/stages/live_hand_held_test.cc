// live_calibrator on videos that behave like a person's hand (tremor, motion
// blur while moving, exposure drift, JPEG): of N held poses at least N - 1
// are kept, none while the target moves, and every pose not kept has its
// reason among the session's notes, said while it was held.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "pipelines/stages/live_calibrator.h"
#include "tests/pipelines/stages/hand_held_video.h"
#include "tests/pipelines/stages/live_test_setup.h"

namespace fs = std::filesystem;

namespace portcal {
namespace {

const char* const kStillsYaml = R"(name: hand_held
seed: 5
num_images: 16
camera: {model: OPENCV, width: 640, height: 480, params: [505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007]}
housing: null
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 20, border_margin_px: 15}
render: {spp: 2, blur_sigma: 0.6, noise_sigma: 2.0}
)";

std::vector<cv::Mat> ReadStills(const fs::path& folder) {
  std::vector<fs::path> paths;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".png") paths.push_back(entry.path());
  }
  std::sort(paths.begin(), paths.end());
  std::vector<cv::Mat> stills;
  for (const fs::path& path : paths) stills.push_back(cv::imread(path.string(), cv::IMREAD_COLOR));
  return stills;
}

// Distinct poses: views whose true corners lie, on average, at least twice
// the session's novelty distance from those of every view chosen before.
std::vector<cv::Mat> DistinctStills(const fs::path& set, const GroundTruth& truth,
                                    double novelty_px) {
  std::vector<const ImageTruth*> chosen;
  std::vector<cv::Mat> stills;
  for (const FrameTruth& frame : truth.images) {
    const ImageTruth& image = frame.cam1;
    bool distinct = true;
    for (const ImageTruth* other : chosen) {
      double sum = 0;
      int shared = 0;
      for (size_t i = 0; i < image.corners_px.size(); ++i) {
        if (!image.corners_px[i] || !other->corners_px[i]) continue;
        sum += (*image.corners_px[i] - *other->corners_px[i]).norm();
        ++shared;
      }
      distinct = distinct && (shared == 0 || sum / shared >= 2 * novelty_px);
    }
    if (!distinct) continue;
    chosen.push_back(&image);
    stills.push_back(cv::imread((set / image.file).string(), cv::IMREAD_COLOR));
  }
  return stills;
}

LiveCalibratorOptions PlayAsFolder(LiveCalibratorOptions options,
                                   const testing::HandHeldVideo& video) {
  options.live.source.folder_fps = video.fps;
  options.live.source.realtime = false;  // every frame, as fast as the session takes them
  options.calibrate_at_end = false;
  return options;
}

// Each hold: a view kept within it, or a note said within it (or on the
// frame that ended it); nothing kept while the target moved.
void ExpectEveryHoldKeptOrExplained(const LiveSummary& session,
                                    const testing::HandHeldVideo& video) {
  const double frame_s = 1 / video.fps;
  int kept_holds = 0;
  for (size_t h = 0; h < video.holds.size(); ++h) {
    const auto [start, end] = video.holds[h];
    const auto within = [&](double t) { return t >= start - 1e-6 && t <= end + frame_s + 1e-6; };
    int kept = 0;
    for (const KeptView& view : session.kept_views) kept += within(view.time_s);
    EXPECT_LE(kept, 1) << "hold " << h << " kept twice";
    kept_holds += kept > 0;
    if (kept > 0) continue;
    std::string said;
    for (const LiveNote& note : session.notes) {
      if (within(note.time_s)) said += note.text + "; ";
    }
    EXPECT_FALSE(said.empty()) << "hold " << h << " (" << start << "-" << end
                               << " s) neither kept nor explained";
    if (!said.empty()) std::cout << "hold " << h << " not kept: " << said << "\n";
  }
  for (const KeptView& view : session.kept_views) {
    bool in_a_hold = false;
    for (const auto& [start, end] : video.holds)
      in_a_hold = in_a_hold || (view.time_s >= start && view.time_s < end);
    EXPECT_TRUE(in_a_hold) << view.name << " at " << view.time_s
                           << " s was taken while the target moved";
  }
  const int n = static_cast<int>(video.holds.size());
  EXPECT_GE(kept_holds, n - 1) << "of " << n << " holds";
  std::cout << kept_holds << " of " << n << " held poses kept\n";
}

TEST(LiveHandHeld, RenderedViewsWithTremorBlurAndJpegAreKeptOrExplained) {
  const testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(dir, kStillsYaml);
  const LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "video").string());
  const std::vector<cv::Mat> stills = DistinctStills(
      dir / "set", truth, options.live.hands_free.novelty_fraction * std::hypot(640.0, 480.0));
  ASSERT_GE(stills.size(), 8u);
  testing::HandHeldVideoOptions hand;
  hand.tremor_px = 1.0;  // the top of a hand's range (the real video's: 0.15 px)
  const testing::HandHeldVideo video = WriteHandHeldVideo(stills, dir / "video", hand);
  const LiveCalibratorSummary summary =
      RunLiveCalibrator(PlayAsFolder(options, video), NoProgress());
  EXPECT_EQ(summary.session.end_reason, "the source ended");
  ExpectEveryHoldKeptOrExplained(summary.session, video);
}

// With a goal and --Live.auto_finish the session ends by itself as soon as
// the expected projection uncertainty is down to the goal, not before.
TEST(LiveHandHeld, AHandsFreeSessionFinishesItselfAtTheGoal) {
  const testing::TempDir dir;
  const GroundTruth truth = testing::RenderSet(dir, kStillsYaml);
  LiveCalibratorOptions options = testing::LiveOptions(dir, (dir / "video").string());
  const std::vector<cv::Mat> stills = DistinctStills(
      dir / "set", truth, options.live.hands_free.novelty_fraction * std::hypot(640.0, 480.0));
  const testing::HandHeldVideo video =
      WriteHandHeldVideo(stills, dir / "video", testing::HandHeldVideoOptions());
  options.live.goal.auto_finish = true;
  options.live.goal.target_uncertainty_px = 0.12;
  const LiveCalibratorSummary summary =
      RunLiveCalibrator(PlayAsFolder(options, video), NoProgress());
  EXPECT_EQ(summary.session.end_reason, "the goal was met (--Live.auto_finish)");
  ASSERT_TRUE(summary.session.estimate && summary.session.estimate->uncertainty.determined);
  EXPECT_LE(summary.session.estimate->uncertainty.mean_px, 0.12);
  EXPECT_LT(summary.session.kept, static_cast<int>(video.holds.size()));
  std::cout << summary.session.kept << " of " << video.holds.size() << " poses kept to reach "
            << summary.session.estimate->uncertainty.mean_px << " px\n";
}

// The shared real in-air views (1440 x 1080, an 8 x 6 board of 3 cm), each
// held 1.5 s with 0.15 px of tremor.
TEST(LiveHandHeld, RealViewsHeldByHandAreKeptOrExplained) {
  PORTCAL_REQUIRE_SHARED(shared);
  const fs::path air = shared / "datasets/real-dome/air";
  if (!fs::exists(air)) GTEST_SKIP() << air << " is absent";
  const testing::TempDir dir;
  const testing::HandHeldVideo video =
      WriteHandHeldVideo(ReadStills(air), dir / "video", testing::HandHeldVideoOptions());
  LiveCalibratorOptions options =
      PlayAsFolder(testing::LiveOptions(dir, (dir / "video").string()), video);
  options.live.detector.chessboard.cols = 8;
  options.live.estimator.guidance.distance_min_m = 0.3;
  options.live.estimator.guidance.distance_max_m = 1.5;
  const LiveCalibratorSummary summary = RunLiveCalibrator(options, NoProgress());
  EXPECT_EQ(summary.session.end_reason, "the source ended");
  ExpectEveryHoldKeptOrExplained(summary.session, video);
}

}  // namespace
}  // namespace portcal
