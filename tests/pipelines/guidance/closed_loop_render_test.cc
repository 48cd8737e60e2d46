// The closed loop with rendered frames: a simulated person holds the board
// where the live estimator suggests (within 5 cm and 5 deg), the frame is
// rendered at that pose (blur, noise) and the board found by the precise
// detector; the estimator calibrates from those views and suggests the
// next. Against random poses from the same range, rendered and detected
// alike. Views are counted until the true expected projection uncertainty
// falls below the goal (the projected-corner version of this test, in
// next_pose_test, runs more seeds; this one checks that the loop holds with
// real detections feeding the estimate).
#include <gtest/gtest.h>

#include "colmap_ext/util/logging.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/synthetic/renderer.h"
#include "pipelines/synthetic/target_builder.h"
#include "tests/pipelines/guidance/simulated_person.h"

namespace portcal {
namespace {

// Renders the 9 x 6 board at a pose and finds it; nullopt unless every
// corner is found.
class RenderingObserver {
 public:
  explicit RenderingObserver(const HousedCamera& truth)
      : rays_(truth.camera, truth.HousingOrNull(), 2, 2),
        target_(BuildTarget(BoardOptions(), PrintLevels())) {
    render_.spp = 2;
    render_.blur_sigma_px = 0.6;
    render_.noise_sigma = 2.0;
    detector_.chessboard.cols = 9;
    detector_.chessboard.rows = 6;
    detector_.square_size_m = 0.03;
  }

  std::optional<CalibrationView> operator()(const Rigid3d& cam_from_target,
                                            std::mt19937_64* rng) const {
    const cv::Mat image =
        RenderImage(rays_, {{target_.object.get(), cam_from_target}}, render_, (*rng)());
    const TargetDetection detection = DetectTarget(image, detector_);
    if (!detection.found || detection.points.size() != 54) return std::nullopt;
    CalibrationView view;
    view.image_name = "frame" + std::to_string((*rng)() % 100000);
    for (const BoardPoint& p : detection.points) {
      view.points_in_target.push_back(p.point_in_target);
      view.pixels.push_back(p.xy);
    }
    return view;
  }

 private:
  static TargetOptions BoardOptions() {
    TargetOptions options;
    options.cols = 9;
    options.rows = 6;
    options.square_size_m = 0.03;
    options.margin_m = 0.015;
    return options;
  }

  RayMap rays_;
  BuiltTarget target_;
  ImageFormationOptions render_;
  TargetDetectorOptions detector_;
};

void ExpectFewerViews(bool housing, double goal_px) {
  const HousedCamera truth{simulated::TrueCamera(),
                           housing ? std::optional<Housing>(simulated::TruePort()) : std::nullopt};
  const RenderingObserver observer(truth);
  const simulated::Observer observe = [&](const Rigid3d& pose, std::mt19937_64* rng) {
    return observer(pose, rng);
  };
  double guided = 0, random = 0;
  const int seeds = 2;
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    guided += simulated::ViewsToReach(housing, true, goal_px, 30, seed, observe);
    random += simulated::ViewsToReach(housing, false, goal_px, 30, seed, observe);
  }
  std::printf(
      "rendered, %s: views to reach %.2f px: suggested %.1f, random %.1f (mean of %d seeds)\n",
      housing ? "flat port" : "camera", goal_px, guided / seeds, random / seeds, seeds);
  EXPECT_LT(guided, 0.67 * random);
}

TEST(ClosedLoopRendered, CameraCalibrationNeedsFewerViewsWithSuggestions) {
  ExpectFewerViews(false, 0.15);
}

TEST(ClosedLoopRendered, HousingCalibrationNeedsFewerViewsWithSuggestions) {
  ExpectFewerViews(true, 0.08);
}

}  // namespace
}  // namespace portcal
