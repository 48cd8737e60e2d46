#include "pipelines/calibration/view_pose.h"

#include <cmath>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/rig_board_error.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

ceres::Solver::Summary SolveCalibration(ceres::Problem* problem, int max_num_iterations,
                                        int num_threads, const std::string& what) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.logging_type = ceres::SILENT;
  options.max_num_iterations = max_num_iterations;
  options.num_threads = num_threads;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
  if (!summary.IsSolutionUsable()) {
    throw NumericalError(what + " did not converge: " + summary.BriefReport());
  }
  return summary;
}

ceres::Covariance::Options CalibrationCovarianceOptions(int num_threads) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.num_threads = num_threads;
  // The ratio of J'J's smallest to largest eigenvalue, from the SVD of J
  // itself: 1e-18 is a singular-value ratio of 1e-9, far above round-off
  // (a true rank deficiency shows ~1e-30), and below what the units alone
  // make of a well-posed calibration (pixels per pixel of focal length next
  // to pixels per metre of pose; the real dome's joint solve over 59 views:
  // between 1e-16 and 1e-14).
  options.min_reciprocal_condition_number = 1e-18;
  return options;
}

void AddRigView(const CalibrationView& view, const HousedCamera& rig_camera,
                double* cam1_from_target, double* camk_from_cam1, double* intrinsics,
                ceres::Problem* problem) {
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

// cam_from_target of one camera and view: homography on the undistorted
// rays, then a pose-only solve through lens and port.
Rigid3d EstimateViewPose(const CalibrationView& view, const HousedCamera& rig_camera,
                         int num_threads) {
  PlanarView planar;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const auto ray = rig_camera.camera.CamFromImg(view.pixels[i]);
    if (!ray) continue;
    planar.target_xy.push_back(view.points_in_target[i].head<2>());
    planar.pixels.push_back(ray->head<2>());
  }
  const std::optional<Rigid3d> pose = PoseFromNormalizedPlanarView(planar);
  if (!pose) throw NumericalError(view.image_name + ": no initial pose from the target");
  PoseBlock p = ToPose(*pose);
  PoseBlock identity = {0, 0, 0, 1, 0, 0, 0};
  std::vector<double> intrinsics = rig_camera.camera.params;
  ceres::Problem problem;
  AddRigView(view, rig_camera, p.data(), identity.data(), intrinsics.data(), &problem);
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
  return FromPose(p);
}

double ViewRms(const CalibrationView& view, const HousedCamera& rig_camera,
               const Rigid3d& cam_from_target) {
  double sum = 0;
  for (size_t i = 0; i < view.pixels.size(); ++i) {
    const auto pixel = rig_camera.Project(cam_from_target * view.points_in_target[i]);
    sum += pixel ? (*pixel - view.pixels[i]).squaredNorm() : 1e6;
  }
  return std::sqrt(sum / std::max<size_t>(1, view.pixels.size()));
}

double HeldOutRms(const std::vector<CalibrationView>& views, const HousedCamera& camera,
                  int num_threads) {
  double sum = 0;
  size_t count = 0;
  for (const CalibrationView& view : views) {
    const double rms = ViewRms(view, camera, EstimateViewPose(view, camera, num_threads));
    sum += rms * rms * view.pixels.size();
    count += view.pixels.size();
  }
  if (count == 0) throw NumericalError("held-out evaluation without points");
  return std::sqrt(sum / count);
}

}  // namespace portcal
