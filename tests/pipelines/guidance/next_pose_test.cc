// Next-pose guidance: the predicted projection uncertainty against the
// spread of repeated calibrations, and the closed loop of a simulated person
// who holds the target where it is suggested (with a person's error) against
// one who holds it anywhere in the same range.
#include "pipelines/guidance/next_pose.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "colmap_ext/util/logging.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/live/live_estimator.h"
#include "pipelines/synthetic/view_sampler.h"

namespace portcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

Camera TrueCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 500, 640, 480);
  camera.params = {505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007};
  return camera;
}

// A 9 x 6 inner-corner chessboard, 3 cm squares.
TargetShape Board() {
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) points.emplace_back(0.03 * c, 0.03 * r, 0);
  }
  return TargetShape::FromPoints(points);
}

NextPoseOptions Options() {
  NextPoseOptions options;
  options.distance_min_m = 0.3;
  options.distance_max_m = 0.9;
  options.tilt_max_deg = 50;
  options.num_candidates = 120;
  options.uncertainty.pixel_sigma_px = 0.2;
  return options;
}

// The corners seen at a pose with Gaussian noise; empty when one leaves the
// image (the detector refuses a cut board).
std::optional<CalibrationView> Observe(const Camera& camera, const TargetShape& target, const Rigid3d& pose,
                                       double sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0, sigma);
  CalibrationView view;
  for (const Eigen::Vector3d& p : target.points) {
    const auto pixel = camera.ImgFromCam(pose * p);
    if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > camera.width || pixel->y() > camera.height) {
      return std::nullopt;
    }
    view.points_in_target.push_back(p);
    view.pixels.push_back(*pixel + Eigen::Vector2d(noise(*rng), noise(*rng)));
  }
  view.image_name = "view" + std::to_string((*rng)() % 100000);
  return view;
}

CalibrationUnknowns Unknowns(const Camera& camera) {
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = camera;
  return unknowns;
}

TEST(ProjectionUncertainty, PredictionMatchesTheSpreadOfRepeatedCalibrations) {
  const Camera truth = TrueCamera();
  const TargetShape board = Board();
  const NextPoseOptions options = Options();
  std::vector<Rigid3d> poses;
  for (const PoseSuggestion& s : OpeningPoses(Unknowns(truth), board, options)) poses.push_back(s.cam_from_target);
  std::mt19937_64 rng(5);
  ViewSamplingOptions sampling;
  sampling.distance_min_m = 0.3;
  sampling.distance_max_m = 0.9;
  sampling.border_margin_px = 20;
  while (poses.size() < 9) {
    poses.push_back(SampleTargetView(truth, nullptr, board.outline, board.center, -Eigen::Vector3d::UnitZ(),
                                     sampling, &rng));
  }
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(8, 8);
  for (const Rigid3d& pose : poses) information += ViewInformation(Unknowns(truth), board.points, pose);
  const ProjectionUncertaintyModel model(Unknowns(truth), options.Uncertainty());
  const ProjectionUncertainty predicted = model.Evaluate(information);
  ASSERT_TRUE(predicted.determined);

  // The same grid points, projected by each of many calibrations.
  const ProjectionUncertaintyOptions grid = options.Uncertainty();
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < grid.grid_rows; ++r) {
    for (int c = 0; c < grid.grid_cols; ++c) {
      const Eigen::Vector3d ray = *truth.CamFromImg(Eigen::Vector2d((c + 0.5) * 640 / grid.grid_cols,
                                                                    (r + 0.5) * 480 / grid.grid_rows));
      points.push_back(ray * grid.working_distance_m / ray.z());
    }
  }
  const int trials = 40;
  std::vector<Eigen::Matrix2d> scatter(points.size(), Eigen::Matrix2d::Zero());
  CameraCalibrationSettings settings;
  settings.initialize_from_data = false;
  for (int t = 0; t < trials; ++t) {
    std::vector<CalibrationView> views;
    for (const Rigid3d& pose : poses) views.push_back(*Observe(truth, board, pose, 0.2, &rng));
    const Camera calibrated = CalibrateCamera(views, truth, settings).camera;
    for (size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector2d error = *calibrated.ImgFromCam(points[k]) - *truth.ImgFromCam(points[k]);
      scatter[k] += error * error.transpose() / trials;
    }
  }
  double empirical = 0;
  for (const Eigen::Matrix2d& s : scatter) {
    empirical += std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s).eigenvalues().maxCoeff());
  }
  empirical /= static_cast<double>(scatter.size());
  // 40 trials give a standard deviation known to about 1/sqrt(2 * 40) =
  // 11 %; the calibrations also refine the poses of noisy views, which the
  // linear prediction only approximates.
  EXPECT_GT(empirical / predicted.mean_px, 0.7) << empirical << " vs " << predicted.mean_px;
  EXPECT_LT(empirical / predicted.mean_px, 1.4) << empirical << " vs " << predicted.mean_px;
}

// A person holding the target near a pose: within 5 cm and 5 degrees.
Rigid3d WithHumanError(const Rigid3d& pose, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(-1, 1);
  Eigen::Vector3d axis(unit(*rng), unit(*rng), unit(*rng));
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(5 * kDeg * std::abs(unit(*rng)), axis.normalized()));
  const Eigen::Vector3d shift = 0.05 * std::abs(unit(*rng)) * Eigen::Vector3d(unit(*rng), unit(*rng), unit(*rng)).normalized();
  // The target turned about its own centre and moved.
  return Rigid3d(pose.rotation * turn, pose.translation + shift);
}

// A flat port 12 mm in front of the lens, its normal 1 deg off the axis;
// the start the person gives: on the axis, 5 mm.
Housing TruePort() {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.0175, -0.0052, 1.0).normalized();
  return Housing::FromName("FLATPORT", {normal.x(), normal.y(), normal.z(), 0.012, 0.008, 1.0, 1.49, 1.334}, "test");
}
Housing StartPort() { return Housing::FromName("FLATPORT", {0, 0, 1, 0.005, 0.008, 1.0, 1.49, 1.334}, "test"); }

// The corners seen through lens and port, with noise; empty when one
// leaves the image.
std::optional<CalibrationView> ObserveHoused(const HousedCamera& camera, const TargetShape& target,
                                             const Rigid3d& pose, double sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0, sigma);
  CalibrationView view;
  for (const Eigen::Vector3d& p : target.points) {
    const auto pixel = camera.Project(pose * p);
    if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > camera.camera.width ||
        pixel->y() > camera.camera.height) {
      return std::nullopt;
    }
    view.points_in_target.push_back(p);
    view.pixels.push_back(*pixel + Eigen::Vector2d(noise(*rng), noise(*rng)));
  }
  view.image_name = "view" + std::to_string(view.pixels.size()) + "_" + std::to_string((*rng)() % 100000);
  return view;
}

// Views a simulated person needs until the true projection uncertainty
// drops below `goal_px`, capped at `max_views`: guided (the live
// estimator's suggestion, held with a person's error) or random poses from
// the same ranges. A camera calibration, or with `housing` a flat port's.
int ViewsToReach(bool housing, bool guided, double goal_px, int max_views, uint64_t seed) {
  const HousedCamera truth{TrueCamera(), housing ? std::optional<Housing>(TruePort()) : std::nullopt};
  const TargetShape board = Board();
  LiveEstimatorOptions estimator_options;
  estimator_options.guidance = Options();
  estimator_options.guidance.seed = seed;
  estimator_options.prior_pixel_sigma_px = 0.2;
  // Nothing known yet: COLMAP's default focal length, no distortion; or
  // the in-air camera and a port on the axis.
  estimator_options.camera = housing ? TrueCamera() : Camera::FromModelName("OPENCV", 1.2 * 640, 640, 480);
  if (housing) estimator_options.housing = StartPort();
  const LiveEstimator estimator(estimator_options, board);
  CalibrationUnknowns true_unknowns = estimator.Unknowns(truth);
  const ProjectionUncertaintyModel true_model(true_unknowns, estimator_options.guidance.Uncertainty());
  std::mt19937_64 rng(seed);
  ViewSamplingOptions sampling;
  sampling.distance_min_m = estimator_options.guidance.distance_min_m;
  sampling.distance_max_m = estimator_options.guidance.distance_max_m;
  sampling.tilt_max_deg = estimator_options.guidance.tilt_max_deg;
  sampling.border_margin_px = estimator_options.guidance.border_margin_px;
  std::shared_ptr<LiveEstimate> estimate;
  std::vector<CalibrationView> views;
  Eigen::MatrixXd true_information = Eigen::MatrixXd::Zero(true_unknowns.NumUnknowns(), true_unknowns.NumUnknowns());
  for (int n = 1; n <= max_views; ++n) {
    if (guided) estimate = std::make_shared<LiveEstimate>(estimator.Estimate(views, estimate.get()));
    std::optional<CalibrationView> view;
    Rigid3d held;
    for (int attempt = 0; attempt < 20 && !view; ++attempt) {
      held = guided && estimate->next ? WithHumanError(estimate->next->cam_from_target, &rng)
                                      : SampleTargetView(truth.camera, truth.HousingOrNull(), board.outline,
                                                         board.center, -Eigen::Vector3d::UnitZ(), sampling, &rng);
      view = ObserveHoused(truth, board, held, 0.2, &rng);
    }
    if (!view) continue;
    views.push_back(*view);
    true_information += ViewInformation(true_unknowns, board.points, held);
    const ProjectionUncertainty reached = true_model.Evaluate(true_information);
    if (reached.determined && reached.mean_px < goal_px) return n;
  }
  return max_views + 1;
}

// Mean views to the goal over a few seeds, guided and random.
std::pair<double, double> MeanViewsToReach(bool housing, double goal_px, int max_views) {
  double guided = 0, random = 0;
  const int seeds = 3;
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    const int with = ViewsToReach(housing, true, goal_px, max_views, seed);
    const int without = ViewsToReach(housing, false, goal_px, max_views, seed);
    LOG(INFO) << (housing ? "housing" : "camera") << " seed " << seed << ": suggested " << with << " views, random "
              << without;
    guided += with;
    random += without;
  }
  std::printf("%s: views to reach %.3f px: suggested %.1f, random %.1f (mean of %d seeds)\n",
              housing ? "flat port" : "camera", goal_px, guided / seeds, random / seeds, seeds);
  return {guided / seeds, random / seeds};
}

TEST(NextPose, SuggestionsReachTheGoalInFewerViewsThanRandomPoses) {
  // At 0.2 px corner noise, points 0.6 m away over the whole image (the
  // corners included): random views of this range level off near 1 px.
  const auto [guided, random] = MeanViewsToReach(false, 0.75, 30);
  // The paper's claim, and by a margin: fewer than two thirds of the views.
  EXPECT_LT(guided, 0.67 * random);
}

TEST(NextPose, SuggestionsAlsoGuideAHousingCalibration) {
  // The port's normal and distance, the in-air camera known: random views
  // of this range stay above 0.3 px after 30 views. Past the opening
  // sequence, so that the search is what is measured.
  const auto [guided, random] = MeanViewsToReach(true, 0.25, 30);
  EXPECT_LT(guided, 0.67 * random);
}

}  // namespace
}  // namespace portcal
