#include "pipelines/calibration/stereo_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/calibration/view_pose.h"
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

void StereoCalibrationSettings::Check() const {
  if (max_num_iterations < 1) {
    throw OptionError("--Stereo.max_num_iterations", max_num_iterations, ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
}

Rigid3d MedianPose(const std::vector<Rigid3d>& poses) {
  PORTCAL_CHECK(!poses.empty());
  // Rotation: start at the chordal mean (sign-aligned quaternions), then
  // Weiszfeld on the geodesic distances.
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  const Eigen::Quaterniond reference = poses[0].rotation.normalized();
  for (const Rigid3d& pose : poses) {
    Eigen::Quaterniond q = pose.rotation.normalized();
    if (q.dot(reference) < 0) q.coeffs() *= -1;
    sum += q.coeffs();
  }
  Eigen::Quaterniond rotation(sum.normalized());
  for (int iter = 0; iter < 100; ++iter) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    double weights = 0;
    for (const Rigid3d& pose : poses) {
      const Eigen::AngleAxisd delta(rotation.conjugate() * pose.rotation.normalized());
      const Eigen::Vector3d v = delta.angle() * delta.axis();
      const double norm = std::max(v.norm(), 1e-12);
      step += v / norm;
      weights += 1 / norm;
    }
    step /= weights;
    rotation = (rotation *
                Eigen::Quaterniond(Eigen::AngleAxisd(
                    step.norm(), step.norm() > 0 ? step.normalized() : Eigen::Vector3d::UnitX())))
                   .normalized();
    if (step.norm() < 1e-12) break;
  }
  // Translation: geometric median.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  for (const Rigid3d& pose : poses)
    translation += pose.translation / static_cast<double>(poses.size());
  for (int iter = 0; iter < 200; ++iter) {
    Eigen::Vector3d numerator = Eigen::Vector3d::Zero();
    double weights = 0;
    for (const Rigid3d& pose : poses) {
      const double distance = std::max((pose.translation - translation).norm(), 1e-12);
      numerator += pose.translation / distance;
      weights += 1 / distance;
    }
    const Eigen::Vector3d next = numerator / weights;
    const bool done = (next - translation).norm() < 1e-14;
    translation = next;
    if (done) break;
  }
  return Rigid3d(rotation, translation);
}

namespace {

// The frames as used (camera 2's board turned where it was numbered from
// the other end), camera 1's pose in each, and the median relative pose.
struct StereoStart {
  std::vector<StereoFrame> used;
  std::vector<PoseBlock> poses1;
  Rigid3d median_cam2_from_cam1;
};

// Whether two candidates for cam2_from_cam1 agree: within kAgreementDeg in
// rotation and kAgreementDistance times the board's distance in position.
// A board numbered from the other end gives a candidate that is off by a
// half turn about the board's normal through its centre, so the two
// hypotheses never come close; a single view's pose is good to a fraction
// of a degree and a percent of the distance.
constexpr double kAgreementDeg = 5;
constexpr double kAgreementDistance = 0.05;

// A frame's two candidates: camera 2's board as numbered and turned by 180
// degrees about its centre, and how far the board is from camera 1.
struct FrameCandidates {
  Rigid3d as_is, turned;
  double board_distance = 0;
};

// How far `candidate` is from the nearer of a frame's two candidates, in
// units of the agreement tolerance (< 1: they agree).
double Disagreement(const Rigid3d& candidate, const FrameCandidates& frame) {
  double best = std::numeric_limits<double>::infinity();
  for (const Rigid3d* other : {&frame.as_is, &frame.turned}) {
    const double rotation =
        candidate.rotation.angularDistance(other->rotation) * 180 / M_PI / kAgreementDeg;
    const double position = (candidate.translation - other->translation).norm() /
                            (kAgreementDistance * frame.board_distance);
    best = std::min(best, std::max(rotation, position));
  }
  return best;
}

// The candidate most frames agree with (ties: the smallest summed
// disagreement). The true relative pose is offered by every frame whose
// views are right up to numbering; a candidate from a board numbered from
// the other end differs from frame to frame (the half turn is about each
// frame's board normal), so it gathers few. A median of all frames'
// candidates would not do: when most frames of camera 2 are numbered from
// the other end (a camera mounted upside down numbers every one that way),
// the median lies among the wrong ones.
Rigid3d ConsensusPose(const std::vector<FrameCandidates>& frames) {
  Rigid3d best;
  int best_support = -1;
  double best_sum = std::numeric_limits<double>::infinity();
  for (const FrameCandidates& frame : frames) {
    for (const Rigid3d* candidate : {&frame.as_is, &frame.turned}) {
      int support = 0;
      double sum = 0;
      for (const FrameCandidates& other : frames) {
        const double disagreement = Disagreement(*candidate, other);
        support += disagreement < 1;
        sum += std::min(disagreement, 1.0);
      }
      if (support > best_support || (support == best_support && sum < best_sum)) {
        best = *candidate;
        best_support = support;
        best_sum = sum;
      }
    }
  }
  return best;
}

// A board that looks the same rotated by 180 degrees (an even number of
// squares) may be numbered from the other end in one camera: each frame
// keeps camera 2's view as numbered or turned by 180 degrees about the
// board centre, whichever agrees with the consensus; the median of the
// kept relative poses starts the adjustment.
StereoStart StartStereo(const std::vector<StereoFrame>& frames, const HousedCamera& camera1,
                        const HousedCamera& camera2, int num_threads) {
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const StereoFrame& frame : frames) {
    for (const auto& p : frame.cam2.points_in_target) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  StereoStart start;
  start.used = frames;
  std::vector<FrameCandidates> candidates;
  std::vector<CalibrationView> flipped;
  for (const StereoFrame& frame : frames) {
    start.poses1.push_back(ToPose(EstimateViewPose(frame.cam1, camera1, num_threads)));
    const Rigid3d target_from_cam1 = FromPose(start.poses1.back()).Inverse();
    CalibrationView view = frame.cam2;
    for (auto& p : view.points_in_target) p.head<2>() = 2 * centre - p.head<2>();
    candidates.push_back({EstimateViewPose(frame.cam2, camera2, num_threads) * target_from_cam1,
                          EstimateViewPose(view, camera2, num_threads) * target_from_cam1,
                          std::max(target_from_cam1.translation.norm(), 1e-6)});
    flipped.push_back(std::move(view));
  }
  const Rigid3d consensus = ConsensusPose(candidates);
  std::vector<Rigid3d> chosen;
  for (size_t f = 0; f < frames.size(); ++f) {
    const double as_is = consensus.rotation.angularDistance(candidates[f].as_is.rotation);
    const double turned = consensus.rotation.angularDistance(candidates[f].turned.rotation);
    if (turned < as_is) {
      start.used[f].cam2 = flipped[f];
      LOG(INFO) << frames[f].cam2.image_name
                << ": board numbered from the other end; turned by 180 deg";
    }
    chosen.push_back(turned < as_is ? candidates[f].turned : candidates[f].as_is);
  }
  start.median_cam2_from_cam1 = MedianPose(chosen);
  return start;
}

// Standard deviations of the relative pose (and of the intrinsics when
// refined) from the covariance scaled by the residual variance.
void ComputeStereoStdDevs(ceres::Problem* problem, const double* cam2_from_cam1,
                          const std::vector<double>& intrinsics1,
                          const std::vector<double>& intrinsics2, double variance,
                          const StereoCalibrationSettings& settings,
                          StereoCalibrationResult* result) {
  ceres::Covariance covariance(CalibrationCovarianceOptions(settings.num_threads));
  std::vector<std::pair<const double*, const double*>> blocks = {{cam2_from_cam1, cam2_from_cam1}};
  if (settings.refine_intrinsics) {
    blocks.emplace_back(intrinsics1.data(), intrinsics1.data());
    blocks.emplace_back(intrinsics2.data(), intrinsics2.data());
  }
  result->camera1_std_dev.assign(intrinsics1.size(), 0.0);
  result->camera2_std_dev.assign(intrinsics2.size(), 0.0);
  if (!covariance.Compute(blocks, problem)) {
    LOG(WARNING)
        << "stereo calibration: rank-deficient covariance; standard deviations undetermined";
    result->rotation_std_dev_deg.setConstant(-1);
    result->translation_std_dev.setConstant(-1);
    return;
  }
  double c[36];
  covariance.GetCovarianceBlockInTangentSpace(cam2_from_cam1, cam2_from_cam1, c);
  // Ceres' quaternion manifold perturbs as exp(delta) * q with the
  // quaternion of delta being (cos|delta|, sin|delta| delta/|delta|): the
  // tangent vector is half the rotation vector.
  for (int i = 0; i < 3; ++i) {
    result->rotation_std_dev_deg[i] =
        2 * std::sqrt(std::max(0.0, c[7 * i] * variance)) * 180 / M_PI;
    result->translation_std_dev[i] = std::sqrt(std::max(0.0, c[7 * (i + 3)] * variance));
  }
  if (!settings.refine_intrinsics) return;
  for (auto [block, out] : {std::pair{&intrinsics1, &result->camera1_std_dev},
                            std::pair{&intrinsics2, &result->camera2_std_dev}}) {
    const int n = static_cast<int>(block->size());
    std::vector<double> k(n * n);
    covariance.GetCovarianceBlock(block->data(), block->data(), k.data());
    for (int i = 0; i < n; ++i) (*out)[i] = std::sqrt(std::max(0.0, k[i * n + i] * variance));
  }
}

// Each frame's two views at the solution: poses and RMS.
void AddStereoViews(const std::vector<StereoFrame>& used, const std::vector<PoseBlock>& poses1,
                    const HousedCamera& camera1, const HousedCamera& camera2,
                    StereoCalibrationResult* result) {
  const HousedCamera final1{result->camera1, camera1.housing},
      final2{result->camera2, camera2.housing};
  for (size_t f = 0; f < used.size(); ++f) {
    const Rigid3d cam1_from_target = FromPose(poses1[f]);
    const Rigid3d cam2_from_target = result->cam2_from_cam1 * cam1_from_target;
    result->views1.push_back({used[f].cam1.image_name, cam1_from_target,
                              ViewRms(used[f].cam1, final1, cam1_from_target),
                              static_cast<int>(used[f].cam1.pixels.size()), false, false});
    result->views2.push_back({used[f].cam2.image_name, cam2_from_target,
                              ViewRms(used[f].cam2, final2, cam2_from_target),
                              static_cast<int>(used[f].cam2.pixels.size()), false, false});
  }
}

}  // namespace

StereoCalibrationResult CalibrateStereo(const std::vector<StereoFrame>& frames,
                                        const HousedCamera& camera1, const HousedCamera& camera2,
                                        const StereoCalibrationSettings& settings) {
  settings.Check();
  if (frames.size() < 2)
    throw NumericalError("stereo calibration needs at least 2 frames seen by both cameras");
  StereoStart start = StartStereo(frames, camera1, camera2, settings.num_threads);
  StereoCalibrationResult result;
  result.median_cam2_from_cam1 = start.median_cam2_from_cam1;
  PoseBlock cam2_from_cam1 = ToPose(result.median_cam2_from_cam1);
  PoseBlock identity = {0, 0, 0, 1, 0, 0, 0};
  std::vector<double> intrinsics1 = camera1.camera.params, intrinsics2 = camera2.camera.params;

  ceres::Problem problem;
  int num_points = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    const StereoFrame& frame = start.used[f];
    AddRigView(frame.cam1, camera1, start.poses1[f].data(), identity.data(), intrinsics1.data(),
               &problem);
    AddRigView(frame.cam2, camera2, start.poses1[f].data(), cam2_from_cam1.data(),
               intrinsics2.data(), &problem);
    problem.SetManifold(start.poses1[f].data(), PoseManifold());
    num_points += static_cast<int>(frame.cam1.pixels.size() + frame.cam2.pixels.size());
  }
  problem.SetParameterBlockConstant(identity.data());
  problem.SetManifold(cam2_from_cam1.data(), PoseManifold());
  if (!settings.refine_intrinsics) {
    problem.SetParameterBlockConstant(intrinsics1.data());
    problem.SetParameterBlockConstant(intrinsics2.data());
  }
  const ceres::Solver::Summary summary = SolveCalibration(
      &problem, settings.max_num_iterations, settings.num_threads, "stereo calibration");

  const double sum_squares = 2 * summary.final_cost;
  const int num_free =
      6 * static_cast<int>(frames.size()) + 6 +
      (settings.refine_intrinsics ? static_cast<int>(intrinsics1.size() + intrinsics2.size()) : 0);
  const double dof = 2.0 * num_points - num_free;
  ComputeStereoStdDevs(&problem, cam2_from_cam1.data(), intrinsics1, intrinsics2,
                       dof > 0 ? sum_squares / dof : 0, settings, &result);
  result.cam2_from_cam1 = FromPose(cam2_from_cam1);
  result.camera1 = camera1.camera;
  result.camera1.params = intrinsics1;
  result.camera2 = camera2.camera;
  result.camera2.params = intrinsics2;
  result.num_points = num_points;
  result.overall_rms_px = std::sqrt(sum_squares / std::max(1, num_points));
  result.residual_sigma_px = dof > 0 ? std::sqrt(sum_squares / dof) : 0;
  AddStereoViews(start.used, start.poses1, camera1, camera2, &result);
  return result;
}

}  // namespace portcal
