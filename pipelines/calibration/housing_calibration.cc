#include "pipelines/calibration/housing_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <cmath>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/autodiff_functor.h"
#include "colmap_ext/cost/virtual_camera_error.h"
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

// Both ports share the layout [a0 a1 a2 b | thickness na ng nw]: the axis
// block (flat: normal, dome: centre), the scalar (flat: int_dist, dome:
// int_radius) and four constants the user gives.
template <typename T>
void AssemblePort(const T* axis, const T* scalar, const double* constants, T* port) {
  port[0] = axis[0];
  port[1] = axis[1];
  port[2] = axis[2];
  port[3] = scalar[0];
  for (int i = 0; i < 4; ++i) port[4 + i] = T(constants[i]);
}

enum class Error { kVirtualCamera, kReprojection };

// A fixed target point seen through lens and port. Blocks: cam_from_target
// (7), intrinsics, axis (3), scalar (1).
template <typename CameraModel, typename Port, Error kError>
struct BoardThroughPortError
    : AutoDiffFunctor<BoardThroughPortError<CameraModel, Port, kError>, 2, 7,
                      CameraModel::kNumParams, 3, 1> {
  BoardThroughPortError(const Eigen::Vector3d& point, const Eigen::Vector2d& observed,
                        const double* constants)
      : point_(point), observed_(observed) {
    std::copy(constants, constants + 4, constants_);
  }

  template <typename T>
  bool operator()(const T* cam_from_target, const T* intrinsics, const T* axis, const T* scalar,
                  T* residual) const {
    T port[8];
    AssemblePort(axis, scalar, constants_, port);
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(cam_from_target);
    const Eigen::Map<const VectorT<T, 3>> translation(cam_from_target + 4);
    const VectorT<T, 3> in_cam = rotation * point_.cast<T>() + translation;
    if constexpr (kError == Error::kVirtualCamera) {
      return VirtualCameraResidual<CameraModel, Port, T>(intrinsics, port, observed_, in_cam, residual);
    } else {
      T x, y;
      if (!ImgFromWater<CameraModel, Port, T>(intrinsics, port, in_cam, &x, &y)) return false;
      residual[0] = x - observed_.x();
      residual[1] = y - observed_.y();
      return true;
    }
  }

 private:
  Eigen::Vector3d point_;
  Eigen::Vector2d observed_;
  double constants_[4];
};

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
  Eigen::Vector3d axis;
  double scalar = 0;
  double constants[4];
  std::vector<Pose> poses;
};

template <Error kError>
void AddResiduals(const std::vector<CalibrationView>& views, int camera_model, int port_model,
                  State* state, ceres::Problem* problem) {
  VisitCameraModel(camera_model, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(port_model, [&](auto port_tag) {
      using Port = decltype(port_tag);
      using Functor = BoardThroughPortError<CameraModel, Port, kError>;
      for (size_t v = 0; v < views.size(); ++v) {
        for (size_t i = 0; i < views[v].pixels.size(); ++i) {
          problem->AddResidualBlock(
              Functor::Create(views[v].points_in_target[i], views[v].pixels[i], state->constants),
              nullptr, state->poses[v].data(), state->intrinsics.data(), state->axis.data(),
              &state->scalar);
        }
      }
    });
  });
}

// Solves poses only (housing and intrinsics fixed); returns the final cost.
double PoseOnlyCost(const std::vector<CalibrationView>& views, int camera_model, int port_model,
                    State* state, int num_threads) {
  ceres::Problem problem;
  AddResiduals<Error::kReprojection>(views, camera_model, port_model, state, &problem);
  for (Pose& pose : state->poses) problem.SetManifold(pose.data(), PoseManifold());
  problem.SetParameterBlockConstant(state->intrinsics.data());
  problem.SetParameterBlockConstant(state->axis.data());
  problem.SetParameterBlockConstant(&state->scalar);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 30;
  options.num_threads = num_threads;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return summary.IsSolutionUsable() ? summary.final_cost : 1e300;
}

}  // namespace

HousingCalibrationResult CalibrateHousing(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const Housing& housing,
                                          const HousingCalibrationSettings& settings) {
  settings.Check();
  camera.Validate("camera");
  housing.Validate("housing");
  if (views.size() < 2) throw NumericalError("housing calibration needs at least 2 views");
  const bool flat = housing.model_id == FlatPort::kId;
  State state;
  state.intrinsics = camera.params;
  state.axis = Eigen::Vector3d(housing.params[0], housing.params[1], housing.params[2]);
  state.scalar = housing.params[3];
  for (int i = 0; i < 4; ++i) state.constants[i] = housing.params[4 + i];
  state.poses = InitialPoses(views, camera);

  HousingCalibrationResult result;
  result.initial_axis = EstimateAxis(views, camera);
  if (settings.initialize_from_data) {
    Eigen::Vector3d axis = result.initial_axis;
    if (flat && axis.z() < 0) axis = -axis;
    // Coarse 1-D search of the magnitude, scored by pose-only residuals.
    // A small decentering makes the dome nearly central, where the F
    // matrices carry little of the axis: the dome's search also walks the
    // camera's own axes.
    std::vector<double> magnitudes;
    std::vector<Eigen::Vector3d> directions = {axis};
    if (flat) {
      for (int i = 0; i < 15; ++i) magnitudes.push_back(1e-3 * std::pow(150.0, i / 14.0));
    } else {
      const double radius = housing.params[3];
      for (int i = -9; i <= 9; ++i) magnitudes.push_back(0.09 * i * radius);
      directions.insert(directions.end(), {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                           Eigen::Vector3d::UnitZ()});
    }
    double best_cost = 1e300;
    State best = state;
    const std::vector<Pose> start_poses = state.poses;
    for (const Eigen::Vector3d& direction : directions) {
      for (const double magnitude : magnitudes) {
        State trial = state;
        trial.poses = start_poses;
        if (flat) {
          trial.axis = direction;
          trial.scalar = magnitude;
        } else {
          trial.axis = magnitude * direction;
        }
        const double cost =
            PoseOnlyCost(views, camera.model_id, housing.model_id, &trial, settings.num_threads);
        if (cost < best_cost) {
          best_cost = cost;
          best = trial;
        }
      }
    }
    state = best;
    LOG(INFO) << "housing_calibrator: axis from the views " << result.initial_axis.transpose()
              << ", start " << state.axis.transpose() << " / " << state.scalar;
  }

  // Joint solves: virtual-camera error first, then the exact reprojection.
  double sum_squares = 0;
  int num_free = 0;
  ceres::Problem final_problem;
  for (const Error error : {Error::kVirtualCamera, Error::kReprojection}) {
    ceres::Problem local;
    ceres::Problem& problem = error == Error::kReprojection ? final_problem : local;
    if (error == Error::kVirtualCamera) {
      AddResiduals<Error::kVirtualCamera>(views, camera.model_id, housing.model_id, &state, &problem);
    } else {
      AddResiduals<Error::kReprojection>(views, camera.model_id, housing.model_id, &state, &problem);
    }
    for (Pose& pose : state.poses) problem.SetManifold(pose.data(), PoseManifold());
    // The intrinsics join only the final, exact solve: the virtual-camera
    // error back-projects through them, which is ill-conditioned far from
    // the solution.
    if (!settings.refine_intrinsics || error == Error::kVirtualCamera) {
      problem.SetParameterBlockConstant(state.intrinsics.data());
    }
    if (flat) {
      problem.SetManifold(state.axis.data(), new ceres::SphereManifold<3>());
    } else {
      problem.SetParameterBlockConstant(&state.scalar);  // the dome radius is given
    }
    sum_squares = 2 * SolveCalibration(&problem, settings.max_num_iterations, settings.num_threads,
                                       "housing calibration")
                          .final_cost;
  }
  // Flat: normal (2 on the sphere) + distance; dome: centre (3).
  num_free = 6 * static_cast<int>(views.size()) + 3 +
             (settings.refine_intrinsics ? static_cast<int>(camera.params.size()) : 0);
  Housing calibrated = housing;
  AssemblePort(state.axis.data(), &state.scalar, state.constants, calibrated.params.data());
  calibrated.Validate("calibrated housing");

  // Standard deviations: covariance scaled by the residual variance.
  int num_points = 0;
  for (const auto& view : views) num_points += static_cast<int>(view.pixels.size());
  const double dof = 2.0 * num_points - num_free;
  const double variance = dof > 0 ? sum_squares / dof : 0;
  ceres::Covariance covariance(CalibrationCovarianceOptions(settings.num_threads));
  std::vector<std::pair<const double*, const double*>> blocks = {{state.axis.data(), state.axis.data()}};
  if (flat) blocks.emplace_back(&state.scalar, &state.scalar);
  if (settings.refine_intrinsics) blocks.emplace_back(state.intrinsics.data(), state.intrinsics.data());
  result.housing_std_dev.assign(8, 0.0);
  result.camera_std_dev.assign(camera.params.size(), 0.0);
  if (covariance.Compute(blocks, &final_problem)) {
    double c[9];
    covariance.GetCovarianceBlock(state.axis.data(), state.axis.data(), c);
    for (int i = 0; i < 3; ++i) result.housing_std_dev[i] = std::sqrt(std::max(0.0, c[4 * i] * variance));
    if (flat) {
      double d;
      covariance.GetCovarianceBlock(&state.scalar, &state.scalar, &d);
      result.housing_std_dev[3] = std::sqrt(std::max(0.0, d * variance));
    }
    if (settings.refine_intrinsics) {
      const int n = static_cast<int>(camera.params.size());
      std::vector<double> k(n * n);
      covariance.GetCovarianceBlock(state.intrinsics.data(), state.intrinsics.data(), k.data());
      for (int i = 0; i < n; ++i) result.camera_std_dev[i] = std::sqrt(std::max(0.0, k[i * n + i] * variance));
    }
  } else {
    // Undetermined (e.g. dome decentering refined together with the
    // principal point): say so rather than report zeros.
    LOG(WARNING) << "housing calibration: the covariance is rank deficient (parameters not "
                    "separable from these views); standard deviations undetermined";
    for (int i = 0; i < (flat ? 4 : 3); ++i) result.housing_std_dev[i] = -1;
    if (settings.refine_intrinsics) {
      std::fill(result.camera_std_dev.begin(), result.camera_std_dev.end(), -1.0);
    }
  }

  result.housing = calibrated;
  result.camera = camera;
  result.camera.params = state.intrinsics;
  result.num_points = num_points;
  result.overall_rms_px = std::sqrt(sum_squares / std::max(1, num_points));
  result.residual_sigma_px = dof > 0 ? std::sqrt(sum_squares / dof) : 0;
  // Per-view RMS with the exact projection.
  for (size_t v = 0; v < views.size(); ++v) {
    CalibratedView out;
    out.image_name = views[v].image_name;
    out.num_points = static_cast<int>(views[v].pixels.size());
    const Pose& p = state.poses[v];
    out.cam_from_target = Rigid3d(Eigen::Quaterniond(p[3], p[0], p[1], p[2]).normalized(),
                                  Eigen::Vector3d(p[4], p[5], p[6]));
    double sum = 0;
    for (size_t i = 0; i < views[v].pixels.size(); ++i) {
      const auto pixel = ProjectPoint(result.camera, &calibrated,
                                      out.cam_from_target * views[v].points_in_target[i]);
      sum += pixel ? (*pixel - views[v].pixels[i]).squaredNorm() : 1e6;
    }
    out.rms_px = std::sqrt(sum / std::max(1, out.num_points));
    result.views.push_back(out);
  }
  return result;
}

}  // namespace portcal
