// Next-pose guidance for a stereo rig: every suggested pose keeps the whole
// target in both cameras' views, and a simulated person holding the target
// where it is suggested reaches a projection uncertainty in both cameras in
// fewer pairs than one holding it anywhere both cameras see it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "colmap_ext/util/logging.h"
#include "pipelines/guidance/live_estimator.h"
#include "pipelines/guidance/next_pose.h"
#include "pipelines/synthetic/view_sampler.h"
#include "tests/pipelines/guidance/simulated_person.h"

namespace portcal {
namespace {

using simulated::Board;
using simulated::TrueCamera;

constexpr double kDeg = M_PI / 180.0;

// Camera 2 12 cm to the right of camera 1, turned 8 deg towards it, with a
// lens of its own (other focal length, principal point and distortion).
Rigid3d Cam2FromCam1() {
  const Rigid3d cam1_from_cam2(
      Eigen::Quaterniond(Eigen::AngleAxisd(-8 * kDeg, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0.12, 0.005, 0));
  return cam1_from_cam2.Inverse();
}

Camera TrueCamera2() {
  Camera camera = TrueCamera();
  camera.params = {512, 509, 318.0, 244.5, -0.18, 0.04, -0.0008, 0.0010};
  return camera;
}

bool Inside(const Camera& camera, const TargetShape& target, const Rigid3d& cam_from_target,
            double margin) {
  for (const Eigen::Vector3d& corner : target.outline) {
    const auto pixel = camera.ImgFromCam(cam_from_target * corner);
    if (!pixel || pixel->x() < margin || pixel->y() < margin ||
        pixel->x() > camera.width - margin || pixel->y() > camera.height - margin) {
      return false;
    }
  }
  return true;
}

std::optional<CalibrationView> Observe(const Camera& camera, const TargetShape& target,
                                       const Rigid3d& pose, std::mt19937_64* rng) {
  if (!Inside(camera, target, pose, 0)) return std::nullopt;
  std::normal_distribution<double> noise(0, 0.2);
  CalibrationView view;
  for (const Eigen::Vector3d& p : target.points) {
    view.points_in_target.push_back(p);
    view.pixels.push_back(*camera.ImgFromCam(pose * p) + Eigen::Vector2d(noise(*rng), noise(*rng)));
  }
  return view;
}

RigUnknowns TrueRig() {
  RigUnknowns rig;
  rig.camera1.camera.camera = TrueCamera();
  rig.camera2.camera.camera = TrueCamera2();
  rig.cam2_from_cam1 = Cam2FromCam1();
  return rig;
}

TEST(RigNextPose, EverySuggestionKeepsTheTargetInBothViews) {
  const RigUnknowns rig = TrueRig();
  const TargetShape board = Board();
  const NextPoseOptions options = simulated::Options();
  const int p1 = rig.camera1.NumUnknowns(), p2 = rig.camera2.NumUnknowns();
  CalibrationInformation information1 = CalibrationInformation::Zero(p1),
                         information2 = CalibrationInformation::Zero(p2);
  for (int kept = 0; kept < 6; ++kept) {
    const PoseSuggestion next =
        SuggestRigPose(rig, board, information1, information2, kept, options);
    EXPECT_EQ(next.opening, kept < 3) << next.why;
    const Rigid3d& pose = next.cam_from_target;
    EXPECT_TRUE(Inside(TrueCamera(), board, pose, options.border_margin_px)) << kept;
    EXPECT_TRUE(Inside(TrueCamera2(), board, rig.cam2_from_cam1 * pose, options.border_margin_px))
        << kept;
    const double distance = (pose * board.center).norm();
    EXPECT_GE(distance, options.distance_min_m - 1e-9);
    EXPECT_LE(distance, options.distance_max_m + 1e-9);
    information1 += ViewInformation(rig.camera1, board.points, pose);
    information2 += ViewInformation(rig.camera2, board.points, rig.cam2_from_cam1 * pose);
    if (kept >= 3) {
      EXPECT_LT(next.after.mean_px, next.before.mean_px) << kept;
    }
  }
}

// Pairs until the worse camera's true projection uncertainty is below
// `goal_px`: guided (EstimateRig's suggestion held with a person's error)
// or random poses both cameras see whole.
int PairsToReach(bool guided, double goal_px, int max_pairs, uint64_t seed) {
  const RigUnknowns truth = TrueRig();
  const TargetShape board = Board();
  LiveEstimatorOptions options;
  options.guidance = simulated::Options();
  options.guidance.seed = seed;
  options.prior_pixel_sigma_px = 0.2;
  options.camera = Camera::FromModelName("OPENCV", 1.2 * 640, 640, 480);
  const LiveEstimator camera1(options, board), camera2(options, board);
  const ProjectionUncertaintyModel model1(truth.camera1, options.guidance.Uncertainty());
  const ProjectionUncertaintyModel model2(truth.camera2, options.guidance.Uncertainty());
  ViewSamplingOptions sampling;
  sampling.distance_min_m = options.guidance.distance_min_m;
  sampling.distance_max_m = options.guidance.distance_max_m;
  sampling.tilt_max_deg = options.guidance.tilt_max_deg;
  sampling.border_margin_px = options.guidance.border_margin_px;
  std::mt19937_64 rng(seed);
  std::shared_ptr<LiveEstimate> estimate;
  std::vector<CalibrationView> views1, views2;
  const int p = truth.camera1.NumUnknowns();
  CalibrationInformation information1 = CalibrationInformation::Zero(p),
                         information2 = information1;
  for (int n = 1; n <= max_pairs; ++n) {
    if (guided)
      estimate = std::make_shared<LiveEstimate>(
          EstimateRig(camera1, camera2, views1, views2, estimate.get()));
    std::optional<CalibrationView> view1, view2;
    Rigid3d held;
    for (int attempt = 0; attempt < 200 && !(view1 && view2); ++attempt) {
      held = guided && estimate->next
                 ? simulated::WithHumanError(estimate->next->cam_from_target, &rng)
                 : SampleTargetView(TrueCamera(), nullptr, board.outline, board.center,
                                    -Eigen::Vector3d::UnitZ(), sampling, &rng);
      view1 = Observe(TrueCamera(), board, held, &rng);
      view2 = Observe(TrueCamera2(), board, truth.cam2_from_cam1 * held, &rng);
    }
    if (!view1 || !view2) continue;
    views1.push_back(*view1);
    views2.push_back(*view2);
    information1 += ViewInformation(truth.camera1, board.points, held);
    information2 += ViewInformation(truth.camera2, board.points, truth.cam2_from_cam1 * held);
    const ProjectionUncertainty reached1 = model1.Evaluate(information1),
                                reached2 = model2.Evaluate(information2);
    if (reached1.determined && reached2.determined &&
        std::max(reached1.mean_px, reached2.mean_px) < goal_px) {
      return n;
    }
  }
  return max_pairs + 1;
}

TEST(RigNextPose, SuggestionsReachTheGoalInFewerPairsThanRandomPoses) {
  double guided = 0, random = 0;
  const int seeds = 2;
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    const int with = PairsToReach(true, 0.15, 30, seed),
              without = PairsToReach(false, 0.15, 30, seed);
    LOG(INFO) << "rig seed " << seed << ": suggested " << with << " pairs, random " << without;
    guided += with;
    random += without;
  }
  std::printf(
      "rig: pairs to reach 0.15 px in both cameras: suggested %.1f, random %.1f (mean of %d "
      "seeds)\n",
      guided / seeds, random / seeds, seeds);
  EXPECT_LT(guided, 0.67 * random);
}

}  // namespace
}  // namespace portcal
