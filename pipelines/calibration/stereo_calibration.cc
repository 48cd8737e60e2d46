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
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

void StereoCalibrationSettings::Check() const {
  if (max_num_iterations < 1) {
    throw OptionError("--Stereo.max_num_iterations", std::to_string(max_num_iterations), ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
}

namespace {

using Pose = std::array<double, 7>;

Pose ToPose(const Rigid3d& rigid) {
  const Eigen::Quaterniond q = rigid.rotation.normalized();
  return {q.x(), q.y(), q.z(), q.w(), rigid.translation.x(), rigid.translation.y(), rigid.translation.z()};
}

Rigid3d FromPose(const Pose& p) {
  return Rigid3d(Eigen::Quaterniond(p[3], p[0], p[1], p[2]).normalized(), Eigen::Vector3d(p[4], p[5], p[6]));
}

// A target point of frame f seen by camera k of the rig: X_k = camk_from_cam1
// * cam1_from_target * X, through the lens and, if Port is not void, the
// port (fixed parameters).
template <typename CameraModel, typename Port>
struct RigBoardError
    : AutoDiffFunctor<RigBoardError<CameraModel, Port>, 2, 7, 7, CameraModel::kNumParams> {
  RigBoardError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed, const std::vector<double>& port)
      : point_(point), observed_(observed), port_(port) {}

  template <typename T>
  bool operator()(const T* cam1_from_target, const T* camk_from_cam1, const T* intrinsics, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q1(cam1_from_target), qk(camk_from_cam1);
    const Eigen::Map<const VectorT<T, 3>> t1(cam1_from_target + 4), tk(camk_from_cam1 + 4);
    const VectorT<T, 3> in_cam = qk * (q1 * point_.cast<T>() + t1) + tk;
    T x, y;
    if constexpr (std::is_void_v<Port>) {
      if (!CameraModel::ImgFromCam(intrinsics, in_cam.x(), in_cam.y(), in_cam.z(), &x, &y)) return false;
    } else {
      T port[Port::kNumParams];
      for (int i = 0; i < Port::kNumParams; ++i) port[i] = T(port_[i]);
      if (!ImgFromWater<CameraModel, Port, T>(intrinsics, port, in_cam, &x, &y)) return false;
    }
    residual[0] = x - observed_.x();
    residual[1] = y - observed_.y();
    return true;
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
  std::vector<double> port_;
};

void AddView(const CalibrationView& view, const RigCamera& rig_camera, double* cam1_from_target,
             double* camk_from_cam1, double* intrinsics, ceres::Problem* problem) {
  VisitCameraModel(rig_camera.camera.model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    const auto add = [&](auto make) {
      for (size_t i = 0; i < view.pixels.size(); ++i) {
        problem->AddResidualBlock(make(view.points_in_target[i], view.pixels[i]), nullptr,
                                  cam1_from_target, camk_from_cam1, intrinsics);
      }
    };
    if (!rig_camera.housing) {
      add([&](const Eigen::Vector3d& p, const Eigen::Vector2d& o) {
        return RigBoardError<CameraModel, void>::Create(p, o, std::vector<double>{});
      });
      return;
    }
    VisitHousingModel(rig_camera.housing->model_id, [&](auto port_tag) {
      using Port = decltype(port_tag);
      add([&](const Eigen::Vector3d& p, const Eigen::Vector2d& o) {
        return RigBoardError<CameraModel, Port>::Create(p, o, rig_camera.housing->params);
      });
    });
  });
}

ceres::Manifold* PoseManifold() {
  return new ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>();
}

// cam_from_target of one camera and view: homography on the undistorted
// rays, then a pose-only solve through lens and port.
Pose InitialPose(const CalibrationView& view, const RigCamera& rig_camera, int num_threads) {
  PlanarView planar;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const auto ray = rig_camera.camera.CamFromImg(view.pixels[i]);
    if (!ray) continue;
    planar.target_xy.push_back(view.points_in_target[i].head<2>());
    planar.pixels.push_back(ray->head<2>());
  }
  const std::optional<Rigid3d> pose = PoseFromNormalizedPlanarView(planar);
  if (!pose) throw NumericalError(view.image_name + ": no initial pose from the target");
  Pose p = ToPose(*pose);
  Pose identity = {0, 0, 0, 1, 0, 0, 0};
  std::vector<double> intrinsics = rig_camera.camera.params;
  ceres::Problem problem;
  AddView(view, rig_camera, p.data(), identity.data(), intrinsics.data(), &problem);
  problem.SetManifold(p.data(), PoseManifold());
  problem.SetParameterBlockConstant(identity.data());
  problem.SetParameterBlockConstant(intrinsics.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.logging_type = ceres::SILENT;
  options.num_threads = num_threads;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw NumericalError(view.image_name + ": pose solve failed");
  return p;
}

double ViewRms(const CalibrationView& view, const RigCamera& rig_camera, const Rigid3d& cam_from_target) {
  double sum = 0;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const auto pixel = ProjectPoint(rig_camera.camera, rig_camera.housing ? &*rig_camera.housing : nullptr,
                                    cam_from_target * view.points_in_target[i]);
    sum += pixel ? (*pixel - view.pixels[i]).squaredNorm() : 1e6;
  }
  return std::sqrt(sum / std::max<size_t>(1, view.pixels.size()));
}

}  // namespace

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

StereoCalibrationResult CalibrateStereo(const std::vector<StereoFrame>& frames, const RigCamera& camera1,
                                        const RigCamera& camera2, const StereoCalibrationSettings& settings) {
  settings.Check();
  if (frames.size() < 2) throw NumericalError("stereo calibration needs at least 2 frames seen by both cameras");
  // A board that looks the same rotated by 180 degrees (an even number of
  // squares) may be numbered from the other end in one camera: each frame
  // also gets camera 2's view rotated by 180 degrees about the board centre,
  // and keeps whichever agrees with the median relative pose.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const StereoFrame& frame : frames) {
    for (const auto& p : frame.cam2.points_in_target) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  std::vector<StereoFrame> used = frames;
  std::vector<Pose> poses1;
  std::vector<Rigid3d> relative, relative_flipped;
  std::vector<CalibrationView> flipped;
  for (const StereoFrame& frame : frames) {
    poses1.push_back(InitialPose(frame.cam1, camera1, settings.num_threads));
    relative.push_back(FromPose(InitialPose(frame.cam2, camera2, settings.num_threads)) *
                       FromPose(poses1.back()).Inverse());
    CalibrationView view = frame.cam2;
    for (auto& p : view.points_in_target) p.head<2>() = 2 * centre - p.head<2>();
    relative_flipped.push_back(FromPose(InitialPose(view, camera2, settings.num_threads)) *
                               FromPose(poses1.back()).Inverse());
    flipped.push_back(std::move(view));
  }
  StereoCalibrationResult result;
  Rigid3d median = MedianPose(relative);
  std::vector<Rigid3d> chosen;
  for (size_t f = 0; f < frames.size(); ++f) {
    const double as_is = median.rotation.angularDistance(relative[f].rotation);
    const double turned = median.rotation.angularDistance(relative_flipped[f].rotation);
    if (turned < as_is) {
      used[f].cam2 = flipped[f];
      LOG(INFO) << frames[f].cam2.image_name << ": board numbered from the other end; turned by 180 deg";
    }
    chosen.push_back(turned < as_is ? relative_flipped[f] : relative[f]);
  }
  result.median_cam2_from_cam1 = MedianPose(chosen);
  Pose cam2_from_cam1 = ToPose(result.median_cam2_from_cam1);
  Pose identity = {0, 0, 0, 1, 0, 0, 0};
  std::vector<double> intrinsics1 = camera1.camera.params, intrinsics2 = camera2.camera.params;

  ceres::Problem problem;
  int num_points = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    AddView(used[f].cam1, camera1, poses1[f].data(), identity.data(), intrinsics1.data(), &problem);
    AddView(used[f].cam2, camera2, poses1[f].data(), cam2_from_cam1.data(), intrinsics2.data(), &problem);
    problem.SetManifold(poses1[f].data(), PoseManifold());
    num_points += static_cast<int>(used[f].cam1.pixels.size() + used[f].cam2.pixels.size());
  }
  problem.SetParameterBlockConstant(identity.data());
  problem.SetManifold(cam2_from_cam1.data(), PoseManifold());
  if (!settings.refine_intrinsics) {
    problem.SetParameterBlockConstant(intrinsics1.data());
    problem.SetParameterBlockConstant(intrinsics2.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.logging_type = ceres::SILENT;
  options.max_num_iterations = settings.max_num_iterations;
  options.num_threads = settings.num_threads;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw NumericalError("stereo calibration did not converge: " + summary.BriefReport());

  const double sum_squares = 2 * summary.final_cost;
  const int num_free = 6 * static_cast<int>(frames.size()) + 6 +
                       (settings.refine_intrinsics ? static_cast<int>(intrinsics1.size() + intrinsics2.size()) : 0);
  const double dof = 2.0 * num_points - num_free;
  const double variance = dof > 0 ? sum_squares / dof : 0;
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = settings.num_threads;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {{cam2_from_cam1.data(), cam2_from_cam1.data()}};
  if (settings.refine_intrinsics) {
    blocks.emplace_back(intrinsics1.data(), intrinsics1.data());
    blocks.emplace_back(intrinsics2.data(), intrinsics2.data());
  }
  result.camera1_std_dev.assign(intrinsics1.size(), 0.0);
  result.camera2_std_dev.assign(intrinsics2.size(), 0.0);
  if (covariance.Compute(blocks, &problem)) {
    double c[36];
    covariance.GetCovarianceBlockInTangentSpace(cam2_from_cam1.data(), cam2_from_cam1.data(), c);
    for (int i = 0; i < 3; ++i) {
      result.rotation_std_dev_deg[i] = std::sqrt(std::max(0.0, c[7 * i] * variance)) * 180 / M_PI;
      result.translation_std_dev[i] = std::sqrt(std::max(0.0, c[7 * (i + 3)] * variance));
    }
    if (settings.refine_intrinsics) {
      for (auto [block, out] : {std::pair{&intrinsics1, &result.camera1_std_dev},
                                std::pair{&intrinsics2, &result.camera2_std_dev}}) {
        const int n = static_cast<int>(block->size());
        std::vector<double> k(n * n);
        covariance.GetCovarianceBlock(block->data(), block->data(), k.data());
        for (int i = 0; i < n; ++i) (*out)[i] = std::sqrt(std::max(0.0, k[i * n + i] * variance));
      }
    }
  } else {
    LOG(WARNING) << "stereo calibration: rank-deficient covariance; standard deviations undetermined";
    result.rotation_std_dev_deg.setConstant(-1);
    result.translation_std_dev.setConstant(-1);
  }

  result.cam2_from_cam1 = FromPose(cam2_from_cam1);
  result.camera1 = camera1.camera;
  result.camera1.params = intrinsics1;
  result.camera2 = camera2.camera;
  result.camera2.params = intrinsics2;
  result.num_points = num_points;
  result.overall_rms_px = std::sqrt(sum_squares / std::max(1, num_points));
  result.residual_sigma_px = dof > 0 ? std::sqrt(sum_squares / dof) : 0;
  const RigCamera final1{result.camera1, camera1.housing}, final2{result.camera2, camera2.housing};
  for (size_t f = 0; f < frames.size(); ++f) {
    const Rigid3d cam1_from_target = FromPose(poses1[f]);
    const Rigid3d cam2_from_target = result.cam2_from_cam1 * cam1_from_target;
    result.views1.push_back({used[f].cam1.image_name, cam1_from_target,
                             ViewRms(used[f].cam1, final1, cam1_from_target),
                             static_cast<int>(used[f].cam1.pixels.size()), false, false});
    result.views2.push_back({used[f].cam2.image_name, cam2_from_target,
                             ViewRms(used[f].cam2, final2, cam2_from_target),
                             static_cast<int>(used[f].cam2.pixels.size()), false, false});
  }
  return result;
}

}  // namespace portcal
