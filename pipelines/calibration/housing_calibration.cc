#include "pipelines/calibration/housing_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_through_port_error.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/calibration/view_pose.h"
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

void HousingCalibrationSettings::Check() const {
  if (max_num_iterations < 1) {
    throw OptionError("--Calibration.max_num_iterations", std::to_string(max_num_iterations), ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
}

namespace {

using Pose = PoseBlock;

// Pose of each view ignoring refraction: homography from the target plane
// to the undistorted rays.
std::vector<Pose> InitialPoses(const std::vector<CalibrationView>& views, const Camera& camera) {
  std::vector<Pose> poses;
  for (const CalibrationView& view : views) {
    std::vector<Eigen::Vector2d> plane, rays;
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      const auto ray = camera.CamFromImg(view.pixels[i]);
      if (!ray) continue;
      plane.push_back(view.points_in_target[i].head<2>());
      rays.push_back(ray->head<2>());
    }
    const std::optional<Rigid3d> pose = PoseFromNormalizedPlanarView({plane, rays});
    if (!pose) throw NumericalError(view.image_name + ": no homography from the target to the image");
    poses.push_back(ToPose(*pose));
  }
  return poses;
}

// The refraction axis as the common left null vector of the views'
// target-to-ray "fundamental matrices" (She et al. 2022).
Eigen::Vector3d EstimateAxis(const std::vector<CalibrationView>& views, const Camera& camera) {
  Eigen::MatrixXd stacked(3, 3 * views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibrationView& view = views[v];
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (const auto& p : view.points_in_target) centroid += p.head<2>();
    centroid /= static_cast<double>(view.points_in_target.size());
    double spread = 0;
    for (const auto& p : view.points_in_target) spread += (p.head<2>() - centroid).norm();
    spread = std::max(1e-9, spread / view.points_in_target.size());
    Eigen::MatrixXd a(view.pixels.size(), 9);
    for (size_t i = 0; i < view.pixels.size(); ++i) {
      const auto ray = camera.CamFromImg(view.pixels[i]);
      const Eigen::Vector3d d = ray ? ray->normalized() : Eigen::Vector3d::Zero();
      const Eigen::Vector2d q = (view.points_in_target[i].head<2>() - centroid) / spread;
      const Eigen::Vector3d p(q.x(), q.y(), 1.0);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) a(i, 3 * r + c) = d[r] * p[c];
      }
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
    const Eigen::VectorXd f = svd.matrixV().col(8);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) stacked(r, 3 * v + c) = f(3 * r + c);
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(stacked, Eigen::ComputeFullU);
  return svd.matrixU().col(2).normalized();
}

struct State {
  std::vector<double> intrinsics;
  Housing housing;  // its params are the port block
  std::vector<Pose> poses;
};

template <PortErrorKind kError>
void AddResiduals(const std::vector<CalibrationView>& views, int camera_model, State* state,
                  ceres::Problem* problem) {
  VisitCameraModel(camera_model, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(state->housing.model_id, [&](auto port_tag) {
      using Port = decltype(port_tag);
      using Functor = BoardThroughPortError<CameraModel, Port, kError>;
      for (size_t v = 0; v < views.size(); ++v) {
        for (size_t i = 0; i < views[v].pixels.size(); ++i) {
          problem->AddResidualBlock(
              Functor::Create(views[v].points_in_target[i], views[v].pixels[i]), nullptr,
              state->poses[v].data(), state->intrinsics.data(), state->housing.params.data());
        }
      }
    });
  });
}

// Solves poses only (housing and intrinsics fixed); returns the final cost.
double PoseOnlyCost(const std::vector<CalibrationView>& views, int camera_model, State* state,
                    int num_threads) {
  ceres::Problem problem;
  AddResiduals<PortErrorKind::kReprojection>(views, camera_model, state, &problem);
  for (Pose& pose : state->poses) problem.SetManifold(pose.data(), PoseManifold());
  problem.SetParameterBlockConstant(state->intrinsics.data());
  problem.SetParameterBlockConstant(state->housing.params.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 30;
  options.num_threads = num_threads;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return summary.IsSolutionUsable() ? summary.final_cost : 1e300;
}

// The start with the smallest pose-only residual among the model's
// candidates for the refraction axis the views show.
State BestStart(const std::vector<CalibrationView>& views, const Camera& camera, const State& state,
                const Eigen::Vector3d& axis, int num_threads) {
  double best_cost = 1e300;
  State best = state;
  for (const Housing& candidate : state.housing.StartCandidates(axis)) {
    State trial = state;
    trial.housing = candidate;
    const double cost = PoseOnlyCost(views, camera.model_id, &trial, num_threads);
    if (cost < best_cost) {
      best_cost = cost;
      best = trial;
    }
  }
  return best;
}

// Joint solves: virtual-camera error first, then the exact reprojection.
// Returns the final sum of squares; `final_problem` keeps the exact one for
// the covariance.
double SolveJointly(const std::vector<CalibrationView>& views, int camera_model,
                    const HousingCalibrationSettings& settings, State* state, ceres::Problem* final_problem) {
  double sum_squares = 0;
  for (const PortErrorKind error : {PortErrorKind::kVirtualCamera, PortErrorKind::kReprojection}) {
    ceres::Problem local;
    ceres::Problem& problem = error == PortErrorKind::kReprojection ? *final_problem : local;
    if (error == PortErrorKind::kVirtualCamera) {
      AddResiduals<PortErrorKind::kVirtualCamera>(views, camera_model, state, &problem);
    } else {
      AddResiduals<PortErrorKind::kReprojection>(views, camera_model, state, &problem);
    }
    for (Pose& pose : state->poses) problem.SetManifold(pose.data(), PoseManifold());
    // The intrinsics join only the final, exact solve: the virtual-camera
    // error back-projects through them, which is ill-conditioned far from
    // the solution.
    if (!settings.refine_intrinsics || error == PortErrorKind::kVirtualCamera) {
      problem.SetParameterBlockConstant(state->intrinsics.data());
    }
    SetHousingRefinement(state->housing, true, state->housing.params.data(), &problem);
    sum_squares = 2 * SolveCalibration(&problem, settings.max_num_iterations, settings.num_threads,
                                       "housing calibration")
                          .final_cost;
  }
  return sum_squares;
}

// Standard deviations from the covariance scaled by the residual variance;
// -1 where the covariance is rank deficient (undetermined).
void FillStdDevs(const HousingCalibrationSettings& settings, double variance, State* state,
                 ceres::Problem* problem, HousingCalibrationResult* result) {
  ceres::Covariance covariance(CalibrationCovarianceOptions(settings.num_threads));
  double* port = state->housing.params.data();
  std::vector<std::pair<const double*, const double*>> blocks = {{port, port}};
  if (settings.refine_intrinsics) blocks.emplace_back(state->intrinsics.data(), state->intrinsics.data());
  const int m = static_cast<int>(state->housing.params.size());
  const int n = static_cast<int>(state->intrinsics.size());
  result->housing_std_dev.assign(static_cast<size_t>(m), 0.0);
  result->camera_std_dev.assign(static_cast<size_t>(n), 0.0);
  const std::vector<int> refined = state->housing.Refinement().Refined();
  if (!covariance.Compute(blocks, problem)) {
    // Undetermined (e.g. dome decentering refined together with the
    // principal point): say so rather than report zeros.
    LOG(WARNING) << "housing calibration: the covariance is rank deficient (parameters not "
                    "separable from these views); standard deviations undetermined";
    for (int k : refined) result->housing_std_dev[static_cast<size_t>(k)] = -1;
    if (settings.refine_intrinsics) std::fill(result->camera_std_dev.begin(), result->camera_std_dev.end(), -1.0);
    return;
  }
  std::vector<double> c(static_cast<size_t>(m * m));
  covariance.GetCovarianceBlock(port, port, c.data());
  for (int k : refined) {
    result->housing_std_dev[static_cast<size_t>(k)] = std::sqrt(std::max(0.0, c[static_cast<size_t>(k * m + k)] * variance));
  }
  if (settings.refine_intrinsics) {
    std::vector<double> k(static_cast<size_t>(n * n));
    covariance.GetCovarianceBlock(state->intrinsics.data(), state->intrinsics.data(), k.data());
    for (int i = 0; i < n; ++i) {
      result->camera_std_dev[static_cast<size_t>(i)] = std::sqrt(std::max(0.0, k[static_cast<size_t>(i * n + i)] * variance));
    }
  }
}

}  // namespace

HousingCalibrationResult CalibrateHousing(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const Housing& housing,
                                          const HousingCalibrationSettings& settings) {
  settings.Check();
  camera.Validate("camera");
  housing.Validate("housing");
  if (views.size() < 2) throw NumericalError("housing calibration needs at least 2 views");
  State state;
  state.intrinsics = camera.params;
  state.housing = housing;
  state.poses = InitialPoses(views, camera);

  HousingCalibrationResult result;
  result.initial_axis = EstimateAxis(views, camera);
  if (settings.initialize_from_data) {
    state = BestStart(views, camera, state, result.initial_axis, settings.num_threads);
    LOG(INFO) << "housing_calibrator: axis from the views " << result.initial_axis.transpose() << ", start "
              << Eigen::Map<const Eigen::VectorXd>(state.housing.params.data(),
                                                   static_cast<Eigen::Index>(state.housing.params.size()))
                     .transpose();
  }
  ceres::Problem final_problem;
  const double sum_squares = SolveJointly(views, camera.model_id, settings, &state, &final_problem);
  const Housing& calibrated = state.housing;
  calibrated.Validate("calibrated housing");

  // Free parameters: the poses, the housing's refined ones (a unit vector
  // has two), the intrinsics when refined.
  const HousingRefinement refinement = calibrated.Refinement();
  const int num_free = 6 * static_cast<int>(views.size()) + (refinement.orientation.empty() ? 0 : 2) +
                       static_cast<int>(refinement.position.size()) +
                       (settings.refine_intrinsics ? static_cast<int>(camera.params.size()) : 0);
  int num_points = 0;
  for (const auto& view : views) num_points += static_cast<int>(view.pixels.size());
  const double dof = 2.0 * num_points - num_free;
  const double variance = dof > 0 ? sum_squares / dof : 0;
  FillStdDevs(settings, variance, &state, &final_problem, &result);

  result.housing = calibrated;
  result.camera = camera;
  result.camera.params = state.intrinsics;
  result.num_points = num_points;
  result.overall_rms_px = std::sqrt(sum_squares / std::max(1, num_points));
  result.residual_sigma_px = dof > 0 ? std::sqrt(sum_squares / dof) : 0;
  const HousedCamera housed{result.camera, calibrated};
  for (size_t v = 0; v < views.size(); ++v) {
    CalibratedView out;
    out.image_name = views[v].image_name;
    out.num_points = static_cast<int>(views[v].pixels.size());
    out.cam_from_target = FromPose(state.poses[v]);
    out.rms_px = ViewRms(views[v], housed, out.cam_from_target);
    result.views.push_back(out);
  }
  return result;
}

}  // namespace portcal
