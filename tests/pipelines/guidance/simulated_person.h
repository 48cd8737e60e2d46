// A simulated person calibrating with next-pose guidance (or without):
// the camera, board and port of the guidance tests, a person's error in
// holding a pose, and the loop that counts the views until the true
// projection uncertainty reaches a goal. The views come from an observer:
// projected corners with noise, or rendered frames and the detector.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <optional>
#include <random>

#include "pipelines/calibration/camera_calibration.h"
#include "pipelines/guidance/live_estimator.h"
#include "pipelines/guidance/next_pose.h"
#include "pipelines/synthetic/view_sampler.h"

namespace portcal::simulated {

inline Camera TrueCamera() {
  Camera camera = Camera::FromModelName("OPENCV", 500, 640, 480);
  camera.params = {505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007};
  return camera;
}

// A 9 x 6 inner-corner chessboard, 3 cm squares.
inline TargetShape Board() {
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) points.emplace_back(0.03 * c, 0.03 * r, 0);
  }
  return TargetShape::FromPoints(points);
}

inline NextPoseOptions Options() {
  NextPoseOptions options;
  options.distance_min_m = 0.3;
  options.distance_max_m = 0.9;
  options.tilt_max_deg = 50;
  options.num_candidates = 120;
  options.uncertainty.pixel_sigma_px = 0.2;
  return options;
}

// A person holding the target near a pose: within 5 cm and 5 degrees.
inline Rigid3d WithHumanError(const Rigid3d& pose, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> unit(-1, 1);
  Eigen::Vector3d axis(unit(*rng), unit(*rng), unit(*rng));
  const Eigen::Quaterniond turn(
      Eigen::AngleAxisd(5 * M_PI / 180 * std::abs(unit(*rng)), axis.normalized()));
  const Eigen::Vector3d shift = 0.05 * std::abs(unit(*rng)) *
                                Eigen::Vector3d(unit(*rng), unit(*rng), unit(*rng)).normalized();
  // The target turned about its origin (a corner) and moved.
  return Rigid3d(pose.rotation * turn, pose.translation + shift);
}

// A flat port 12 mm in front of the lens, its normal 1 deg off the axis;
// the start the person gives: on the axis, 5 mm.
inline Housing TruePort() {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.0175, -0.0052, 1.0).normalized();
  return Housing::FromName(
      "FLATPORT", {normal.x(), normal.y(), normal.z(), 0.012, 0.008, 1.0, 1.49, 1.334}, "test");
}
inline Housing StartPort() {
  return Housing::FromName("FLATPORT", {0, 0, 1, 0.005, 0.008, 1.0, 1.49, 1.334}, "test");
}

// Views a simulated person needs until the true projection uncertainty
// drops below `goal_px`, capped at `max_views`: guided (the live
// estimator's suggestion, held with a person's error) or random poses from
// the same ranges. A camera calibration, or with `housing` a flat port's.
// What a view held at a pose shows (nullopt: the target is not found).
using Observer = std::function<std::optional<CalibrationView>(const Rigid3d& cam_from_target,
                                                              std::mt19937_64* rng)>;

inline int ViewsToReach(bool housing, bool guided, double goal_px, int max_views, uint64_t seed,
                        const Observer& observe) {
  const HousedCamera truth{TrueCamera(),
                           housing ? std::optional<Housing>(TruePort()) : std::nullopt};
  const TargetShape board = Board();
  LiveEstimatorOptions estimator_options;
  estimator_options.guidance = Options();
  estimator_options.guidance.seed = seed;
  estimator_options.prior_pixel_sigma_px = 0.2;
  // Nothing known yet: COLMAP's default focal length, no distortion; or
  // the in-air camera and a port on the axis.
  estimator_options.camera =
      housing ? TrueCamera() : Camera::FromModelName("OPENCV", 1.2 * 640, 640, 480);
  if (housing) estimator_options.housing = StartPort();
  const LiveEstimator estimator(estimator_options, board);
  CalibrationUnknowns true_unknowns = estimator.Unknowns(truth);
  const ProjectionUncertaintyModel true_model(true_unknowns,
                                              estimator_options.guidance.Uncertainty());
  std::mt19937_64 rng(seed);
  ViewSamplingOptions sampling;
  sampling.distance_min_m = estimator_options.guidance.distance_min_m;
  sampling.distance_max_m = estimator_options.guidance.distance_max_m;
  sampling.tilt_max_deg = estimator_options.guidance.tilt_max_deg;
  sampling.border_margin_px = estimator_options.guidance.border_margin_px;
  std::shared_ptr<LiveEstimate> estimate;
  std::vector<CalibrationView> views;
  CalibrationInformation true_information =
      CalibrationInformation::Zero(true_unknowns.NumUnknowns());
  for (int n = 1; n <= max_views; ++n) {
    if (guided)
      estimate = std::make_shared<LiveEstimate>(estimator.Estimate(views, estimate.get()));
    std::optional<CalibrationView> view;
    Rigid3d held;
    for (int attempt = 0; attempt < 20 && !view; ++attempt) {
      held = guided && estimate->next
                 ? WithHumanError(estimate->next->cam_from_target, &rng)
                 : SampleTargetView(truth.camera, truth.HousingOrNull(), board.outline,
                                    board.center, -Eigen::Vector3d::UnitZ(), sampling, &rng);
      view = observe(held, &rng);
    }
    if (!view) continue;
    views.push_back(*view);
    true_information += ViewInformation(true_unknowns, board.points, held);
    const ProjectionUncertainty reached = true_model.Evaluate(true_information);
    if (reached.determined && reached.mean_px < goal_px) return n;
  }
  return max_views + 1;
}

}  // namespace portcal::simulated
