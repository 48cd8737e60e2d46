#include "pipelines/calibration/stereo_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>

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
    throw OptionError("--Stereo.max_num_iterations", std::to_string(max_num_iterations), ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
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
    rotation = (rotation * Eigen::Quaterniond(Eigen::AngleAxisd(step.norm(), step.norm() > 0 ? step.normalized()
                                                                                          : Eigen::Vector3d::UnitX())))
                   .normalized();
    if (step.norm() < 1e-12) break;
  }
  // Translation: geometric median.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  for (const Rigid3d& pose : poses) translation += pose.translation / static_cast<double>(poses.size());
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

// A board that looks the same rotated by 180 degrees (an even number of
// squares) may be numbered from the other end in one camera: each frame
// also gets camera 2's view rotated by 180 degrees about the board centre,
// and keeps whichever agrees with the median relative pose.
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
  std::vector<Rigid3d> relative, relative_flipped;
  std::vector<CalibrationView> flipped;
  for (const StereoFrame& frame : frames) {
    start.poses1.push_back(ToPose(EstimateViewPose(frame.cam1, camera1, num_threads)));
    const Rigid3d target_from_cam1 = FromPose(start.poses1.back()).Inverse();
    relative.push_back(EstimateViewPose(frame.cam2, camera2, num_threads) * target_from_cam1);
    CalibrationView view = frame.cam2;
    for (auto& p : view.points_in_target) p.head<2>() = 2 * centre - p.head<2>();
    relative_flipped.push_back(EstimateViewPose(view, camera2, num_threads) * target_from_cam1);
    flipped.push_back(std::move(view));
  }
  const Rigid3d median = MedianPose(relative);
  std::vector<Rigid3d> chosen;
  for (size_t f = 0; f < frames.size(); ++f) {
    const double as_is = median.rotation.angularDistance(relative[f].rotation);
    const double turned = median.rotation.angularDistance(relative_flipped[f].rotation);
    if (turned < as_is) {
      start.used[f].cam2 = flipped[f];
      LOG(INFO) << frames[f].cam2.image_name << ": board numbered from the other end; turned by 180 deg";
    }
    chosen.push_back(turned < as_is ? relative_flipped[f] : relative[f]);
  }
  start.median_cam2_from_cam1 = MedianPose(chosen);
  return start;
}

// Standard deviations of the relative pose (and of the intrinsics when
// refined) from the covariance scaled by the residual variance.
void ComputeStereoStdDevs(ceres::Problem* problem, const double* cam2_from_cam1, const std::vector<double>& intrinsics1,
                          const std::vector<double>& intrinsics2, double variance,
                          const StereoCalibrationSettings& settings, StereoCalibrationResult* result) {
  ceres::Covariance covariance(CalibrationCovarianceOptions(settings.num_threads));
  std::vector<std::pair<const double*, const double*>> blocks = {{cam2_from_cam1, cam2_from_cam1}};
  if (settings.refine_intrinsics) {
    blocks.emplace_back(intrinsics1.data(), intrinsics1.data());
    blocks.emplace_back(intrinsics2.data(), intrinsics2.data());
  }
  result->camera1_std_dev.assign(intrinsics1.size(), 0.0);
  result->camera2_std_dev.assign(intrinsics2.size(), 0.0);
  if (!covariance.Compute(blocks, problem)) {
    LOG(WARNING) << "stereo calibration: rank-deficient covariance; standard deviations undetermined";
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
    result->rotation_std_dev_deg[i] = 2 * std::sqrt(std::max(0.0, c[7 * i] * variance)) * 180 / M_PI;
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
                    const HousedCamera& camera1, const HousedCamera& camera2, StereoCalibrationResult* result) {
  const HousedCamera final1{result->camera1, camera1.housing}, final2{result->camera2, camera2.housing};
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

StereoCalibrationResult CalibrateStereo(const std::vector<StereoFrame>& frames, const HousedCamera& camera1,
                                        const HousedCamera& camera2, const StereoCalibrationSettings& settings) {
  settings.Check();
  if (frames.size() < 2) throw NumericalError("stereo calibration needs at least 2 frames seen by both cameras");
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
    AddRigView(frame.cam1, camera1, start.poses1[f].data(), identity.data(), intrinsics1.data(), &problem);
    AddRigView(frame.cam2, camera2, start.poses1[f].data(), cam2_from_cam1.data(), intrinsics2.data(), &problem);
    problem.SetManifold(start.poses1[f].data(), PoseManifold());
    num_points += static_cast<int>(frame.cam1.pixels.size() + frame.cam2.pixels.size());
  }
  problem.SetParameterBlockConstant(identity.data());
  problem.SetManifold(cam2_from_cam1.data(), PoseManifold());
  if (!settings.refine_intrinsics) {
    problem.SetParameterBlockConstant(intrinsics1.data());
    problem.SetParameterBlockConstant(intrinsics2.data());
  }
  const ceres::Solver::Summary summary =
      SolveCalibration(&problem, settings.max_num_iterations, settings.num_threads, "stereo calibration");

  const double sum_squares = 2 * summary.final_cost;
  const int num_free = 6 * static_cast<int>(frames.size()) + 6 +
                       (settings.refine_intrinsics ? static_cast<int>(intrinsics1.size() + intrinsics2.size()) : 0);
  const double dof = 2.0 * num_points - num_free;
  ComputeStereoStdDevs(&problem, cam2_from_cam1.data(), intrinsics1, intrinsics2, dof > 0 ? sum_squares / dof : 0,
                       settings, &result);
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
