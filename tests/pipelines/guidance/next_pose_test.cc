// Next-pose guidance: the predicted projection uncertainty against the
// spread of repeated calibrations, and the closed loop of a simulated person
// who holds the target where it is suggested (with a person's error) against
// one who holds it anywhere in the same range.
#include "pipelines/guidance/next_pose.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/calibration/housing_calibration.h"
#include "pipelines/guidance/live_estimator.h"
#include "pipelines/synthetic/view_sampler.h"
#include "tests/pipelines/guidance/simulated_person.h"

namespace portcal {
namespace {

using simulated::Board;
using simulated::Options;
using simulated::TrueCamera;

constexpr double kDeg = M_PI / 180.0;

// The corners seen at a pose with Gaussian noise; empty when one leaves the
// image (the detector refuses a cut board).
std::optional<CalibrationView> Observe(const Camera& camera, const TargetShape& target,
                                       const Rigid3d& pose, double sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0, sigma);
  CalibrationView view;
  for (const Eigen::Vector3d& p : target.points) {
    const auto pixel = camera.ImgFromCam(pose * p);
    if (!pixel || pixel->x() < 0 || pixel->y() < 0 || pixel->x() > camera.width ||
        pixel->y() > camera.height) {
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

// The lenses the prediction is checked on: mrcal has the first; the other
// two only portcal.
Camera LensOfModel(const std::string& model) {
  if (model == "OPENCV") return TrueCamera();
  Camera camera = Camera::FromModelName(model, 500, 640, 480);
  if (model == "OPENCV_FISHEYE")
    camera.params = {402, 398, 321.5, 242.0, 0.03, -0.012, 0.004, -0.001};
  if (model == "RADIAL") camera.params = {502, 322.5, 238.0, -0.18, 0.05};
  return camera;
}

// A camera point held to the targets' frames, as mrcal's own Monte Carlo
// test maps it: into every target frame with the true pose, back with the
// re-solved one, averaged.
Eigen::Vector3d MovedWithTheFrames(const Eigen::Vector3d& point,
                                   const std::vector<Rigid3d>& true_poses,
                                   const std::vector<CalibratedView>& solved) {
  Eigen::Vector3d moved = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < true_poses.size(); ++i) {
    moved += solved[i].cam_from_target * (true_poses[i].Inverse() * point) /
             static_cast<double>(true_poses.size());
  }
  return moved;
}

// The mean over the grid of each point's worst-direction spread.
double MeanWorstSpread(const std::vector<Eigen::Matrix2d>& scatter) {
  double sum = 0;
  for (const Eigen::Matrix2d& s : scatter) {
    sum += std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(s).eigenvalues().maxCoeff());
  }
  return sum / static_cast<double>(scatter.size());
}

// Predicted (mean-frames) against the spread of many calibrations of the
// same views re-noised, each projection compared as mrcal's own Monte
// Carlo test does: the point mapped into every target frame with the true
// pose and back with the re-solved one, averaged, then projected by the
// re-solved lens.
void ExpectPredictionMatchesTheSpread(const std::string& model) {
  const Camera truth = LensOfModel(model);
  const TargetShape board = Board();
  const NextPoseOptions options = Options();
  std::vector<Rigid3d> poses;
  for (const PoseSuggestion& s : OpeningPoses(Unknowns(truth), board, options))
    poses.push_back(s.cam_from_target);
  std::mt19937_64 rng(7);
  ViewSamplingOptions sampling;
  sampling.distance_min_m = 0.3;
  sampling.distance_max_m = 0.9;
  sampling.border_margin_px = 20;
  while (poses.size() < 9) {
    poses.push_back(SampleTargetView(truth, nullptr, board.outline, board.center,
                                     -Eigen::Vector3d::UnitZ(), sampling, &rng));
  }
  const int p = static_cast<int>(truth.params.size());
  CalibrationInformation information = CalibrationInformation::Zero(p);
  for (const Rigid3d& pose : poses)
    information += ViewInformation(Unknowns(truth), board.points, pose);
  const ProjectionUncertaintyModel uncertainty(Unknowns(truth), options.Uncertainty());
  const ProjectionUncertainty predicted = uncertainty.Evaluate(information);
  ASSERT_TRUE(predicted.determined);

  // The same grid points, projected by each of many calibrations.
  const ProjectionUncertaintyOptions grid = options.Uncertainty();
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < grid.grid_rows; ++r) {
    for (int c = 0; c < grid.grid_cols; ++c) {
      const Eigen::Vector3d ray = *truth.CamFromImg(
          Eigen::Vector2d((c + 0.5) * 640 / grid.grid_cols, (r + 0.5) * 480 / grid.grid_rows));
      points.push_back(ray * grid.working_distance_m / ray.z());
    }
  }
  const int trials = 100;
  std::vector<Eigen::Matrix2d> scatter(points.size(), Eigen::Matrix2d::Zero());
  CameraCalibrationSettings settings;
  settings.initialize_from_data = false;
  for (int t = 0; t < trials; ++t) {
    std::vector<CalibrationView> views;
    for (const Rigid3d& pose : poses) views.push_back(*Observe(truth, board, pose, 0.2, &rng));
    const CameraCalibrationResult solved = CalibrateCamera(views, truth, settings);
    for (size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector3d moved = MovedWithTheFrames(points[k], poses, solved.views);
      const Eigen::Vector2d error = *solved.camera.ImgFromCam(moved) - *truth.ImgFromCam(points[k]);
      scatter[k] += error * error.transpose() / trials;
    }
  }
  const double empirical = MeanWorstSpread(scatter);
  std::printf(
      "%s projection uncertainty (mean-frames): predicted %.4f px, spread of %d calibrations %.4f "
      "px "
      "(ratio %.2f)\n",
      model.c_str(), predicted.mean_px, trials, empirical, empirical / predicted.mean_px);
  // 100 trials give a standard deviation known to about 1/sqrt(2 * 100)
  // = 7 % (at one point; the grid's points are correlated, so its mean is
  // hardly steadier); 20 %, as the issue asks, allows near three of those.
  EXPECT_GT(empirical / predicted.mean_px, 0.8) << empirical << " vs " << predicted.mean_px;
  EXPECT_LT(empirical / predicted.mean_px, 1.2) << empirical << " vs " << predicted.mean_px;
}

TEST(ProjectionUncertainty, PredictionMatchesTheSpreadOfRepeatedCalibrationsOpenCv) {
  ExpectPredictionMatchesTheSpread("OPENCV");
}

TEST(ProjectionUncertainty, PredictionMatchesTheSpreadOfRepeatedCalibrationsFisheye) {
  ExpectPredictionMatchesTheSpread("OPENCV_FISHEYE");
}

TEST(ProjectionUncertainty, PredictionMatchesTheSpreadOfRepeatedCalibrationsRadial) {
  ExpectPredictionMatchesTheSpread("RADIAL");
}

// The corners seen through lens and port, with noise; empty when one
// leaves the image.
std::optional<CalibrationView> ObserveHoused(const HousedCamera& camera, const TargetShape& target,
                                             const Rigid3d& pose, double sigma,
                                             std::mt19937_64* rng) {
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
  view.image_name =
      "view" + std::to_string(view.pixels.size()) + "_" + std::to_string((*rng)() % 100000);
  return view;
}

// Behind a flat port (the in-air lens given, as housing_calibrator does by
// default), where mrcal has no model: the same views re-noised and the
// port re-solved each time; a grid point in water held to the targets'
// frames as above, projected through the re-solved port.
TEST(ProjectionUncertainty, PredictionMatchesTheSpreadOfRepeatedHousingCalibrations) {
  const HousedCamera truth{TrueCamera(), simulated::TruePort()};
  CalibrationUnknowns unknowns;
  unknowns.camera = truth;
  unknowns.housing_calibration = true;
  const TargetShape board = Board();
  const NextPoseOptions options = Options();
  std::vector<Rigid3d> poses;
  for (const PoseSuggestion& s : OpeningPoses(unknowns, board, options))
    poses.push_back(s.cam_from_target);
  std::mt19937_64 rng(11);
  ViewSamplingOptions sampling;
  sampling.distance_min_m = 0.3;
  sampling.distance_max_m = 0.9;
  sampling.border_margin_px = 20;
  while (poses.size() < 9) {
    poses.push_back(SampleTargetView(truth.camera, truth.HousingOrNull(), board.outline,
                                     board.center, -Eigen::Vector3d::UnitZ(), sampling, &rng));
  }
  CalibrationInformation information = CalibrationInformation::Zero(unknowns.NumUnknowns());
  for (const Rigid3d& pose : poses) information += ViewInformation(unknowns, board.points, pose);
  const ProjectionUncertaintyOptions grid = options.Uncertainty();
  const ProjectionUncertainty predicted =
      ProjectionUncertaintyModel(unknowns, grid).Evaluate(information);
  ASSERT_TRUE(predicted.determined);
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < grid.grid_rows; ++r) {
    for (int c = 0; c < grid.grid_cols; ++c) {
      const Ray3d ray = *truth.Unproject(
          Eigen::Vector2d((c + 0.5) * 640 / grid.grid_cols, (r + 0.5) * 480 / grid.grid_rows));
      points.push_back(ray.origin + (grid.working_distance_m - ray.origin.z()) / ray.direction.z() *
                                        ray.direction);
    }
  }
  const int trials = 100;
  std::vector<Eigen::Matrix2d> scatter(points.size(), Eigen::Matrix2d::Zero());
  HousingCalibrationSettings settings;
  settings.initialize_from_data = false;
  for (int t = 0; t < trials; ++t) {
    std::vector<CalibrationView> views;
    for (const Rigid3d& pose : poses)
      views.push_back(*ObserveHoused(truth, board, pose, 0.2, &rng));
    const HousingCalibrationResult solved =
        CalibrateHousing(views, truth.camera, *truth.housing, settings);
    const HousedCamera camera{truth.camera, solved.housing};
    for (size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector2d error =
          *camera.Project(MovedWithTheFrames(points[k], poses, solved.views)) -
          *truth.Project(points[k]);
      scatter[k] += error * error.transpose() / trials;
    }
  }
  const double empirical = MeanWorstSpread(scatter);
  std::printf(
      "flat port projection uncertainty (mean-frames): predicted %.4f px, spread of %d "
      "calibrations %.4f px "
      "(ratio %.2f)\n",
      predicted.mean_px, trials, empirical, empirical / predicted.mean_px);
  EXPECT_GT(empirical / predicted.mean_px, 0.8) << empirical << " vs " << predicted.mean_px;
  EXPECT_LT(empirical / predicted.mean_px, 1.2) << empirical << " vs " << predicted.mean_px;
}

// Mean views to the goal over a few seeds, guided and random.
std::pair<double, double> MeanViewsToReach(bool housing, double goal_px, int max_views) {
  double guided = 0, random = 0;
  const int seeds = 3;
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    const HousedCamera truth{
        TrueCamera(), housing ? std::optional<Housing>(simulated::TruePort()) : std::nullopt};
    const simulated::Observer observe = [&](const Rigid3d& pose, std::mt19937_64* rng) {
      return ObserveHoused(truth, Board(), pose, 0.2, rng);
    };
    const int with = simulated::ViewsToReach(housing, true, goal_px, max_views, seed, observe);
    const int without = simulated::ViewsToReach(housing, false, goal_px, max_views, seed, observe);
    LOG(INFO) << (housing ? "housing" : "camera") << " seed " << seed << ": suggested " << with
              << " views, random " << without;
    guided += with;
    random += without;
  }
  std::printf("%s: views to reach %.3f px: suggested %.1f, random %.1f (mean of %d seeds)\n",
              housing ? "flat port" : "camera", goal_px, guided / seeds, random / seeds, seeds);
  return {guided / seeds, random / seeds};
}

TEST(NextPose, ARangeWhereTheTargetCannotFitIsAnErrorNamingIt) {
  NextPoseOptions options = Options();
  options.distance_min_m = 0.05;  // the board fills more than the image
  options.distance_max_m = 0.08;
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = TrueCamera();
  try {
    SuggestPoses(unknowns, Board(), CalibrationInformation::Zero(8), 0, 1, options);
    ADD_FAILURE() << "a suggestion where the target cannot fit";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("--Live.distance_range"), std::string::npos) << e.what();
  }
}

TEST(NextPose, SuggestionsReachTheGoalInFewerViewsThanRandomPoses) {
  // At 0.2 px corner noise, points 0.6 m away over the whole image (the
  // corners included), mrcal's measure: random views of this range are
  // still at 0.17-0.18 px after 30 views (docs/live.md).
  const auto [guided, random] = MeanViewsToReach(false, 0.15, 30);
  // The paper's claim, and by a margin: fewer than two thirds of the views.
  EXPECT_LT(guided, 0.67 * random);
}

TEST(NextPose, SuggestionsAlsoGuideAHousingCalibration) {
  // The port's normal and distance, the in-air camera known: random views
  // of this range reach 0.08 px only after 25-30 views. Past the opening
  // sequence, so that the search is what is measured.
  const auto [guided, random] = MeanViewsToReach(true, 0.08, 30);
  EXPECT_LT(guided, 0.67 * random);
}

}  // namespace
}  // namespace portcal
