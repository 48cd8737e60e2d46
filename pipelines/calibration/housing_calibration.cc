#include "pipelines/calibration/housing_calibration.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <memory>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_reprojection_error.h"
#include "colmap_ext/cost/board_through_port_error.h"
#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/calibration/held_block_covariance.h"
#include "pipelines/calibration/view_pose.h"
#include "pipelines/calibration/zhang_initialization.h"

namespace portcal {

void HousingCalibrationSettings::Check() const {
  if (max_num_iterations < 1) {
    throw OptionError("--Calibration.max_num_iterations", max_num_iterations, ">= 1");
  }
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
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
    if (!pose)
      throw NumericalError(view.image_name + ": no homography from the target to the image");
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
  Housing housing;                             // its params are the port block
  std::vector<Pose> poses;                     // the underwater views'
  std::vector<Pose> in_air_poses;              // the in-air views'
  std::array<double, 2> warp = {0, 0};         // the underwater board's
  std::array<double, 2> in_air_warp = {0, 0};  // a different in-air board's
  // 1 / residual variance of each set (px^-2): the joint solve's weights.
  double water_weight = 1, air_weight = 1;
};

// The views and what the solve does with them.
struct Inputs {
  const std::vector<CalibrationView>& views;
  const InAirViews* in_air;  // null: none
  int camera_model;
  Eigen::Vector4d board_extent;         // the underwater views' (and shared in-air's)
  Eigen::Vector4d in_air_board_extent;  // the in-air views' own warp's
  const HousingCalibrationSettings& settings;
  const Eigen::MatrixXd* lens_covariance;  // null: none given
  bool RefinesIntrinsics() const { return settings.refine_intrinsics || in_air != nullptr; }
};

// A Ceres problem with its residual blocks per view (to weigh each set
// and measure each view) and the weights' losses, which outlive it.
struct JointProblem {
  std::unique_ptr<ceres::LossFunction> water_loss, air_loss;
  ceres::Problem problem{LossesNotOwned()};
  std::vector<std::vector<ceres::ResidualBlockId>> water_ids, air_ids;

  static ceres::Problem::Options LossesNotOwned() {
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    return options;
  }
};

// The board's extent over both sets when they share a warp.
Eigen::Vector4d SharedBoardExtent(const std::vector<CalibrationView>& views,
                                  const InAirViews* in_air) {
  Eigen::Vector4d extent = BoardExtent(views);
  if (in_air != nullptr && in_air->share_board_warp) {
    for (const CalibrationView& view : in_air->views) ExtendBoardExtent(view, &extent);
  }
  return extent;
}

// A weight as a loss: rho(s) = w s, so the covariance sees the weighted
// Jacobian too.
ceres::LossFunction* WeightLoss(double weight, std::unique_ptr<ceres::LossFunction>* holder) {
  if (weight == 1) return nullptr;
  holder->reset(new ceres::ScaledLoss(nullptr, weight, ceres::DO_NOT_TAKE_OWNERSHIP));
  return holder->get();
}

template <PortErrorKind kError>
void AddWaterResiduals(const Inputs& in, State* state, JointProblem* jp) {
  ceres::LossFunction* loss = WeightLoss(state->water_weight, &jp->water_loss);
  VisitCameraModel(in.camera_model, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    VisitHousingModel(state->housing.model_id, [&](auto port_tag) {
      using Functor = WarpedBoardThroughPortError<CameraModel, decltype(port_tag), kError>;
      for (size_t v = 0; v < in.views.size(); ++v) {
        const CalibrationView& view = in.views[v];
        jp->water_ids.emplace_back();
        for (size_t i = 0; i < view.pixels.size(); ++i) {
          const Eigen::Vector3d& p = view.points_in_target[i];
          jp->water_ids.back().push_back(jp->problem.AddResidualBlock(
              Functor::Create(p, BoardWarpUv(p, in.board_extent), view.pixels[i]), loss,
              state->poses[v].data(), state->intrinsics.data(), state->housing.params.data(),
              state->warp.data()));
        }
      }
    });
  });
}

void AddAirResiduals(const Inputs& in, State* state, JointProblem* jp) {
  ceres::LossFunction* loss = WeightLoss(state->air_weight, &jp->air_loss);
  const bool shared = in.in_air->share_board_warp;
  double* warp = shared ? state->warp.data() : state->in_air_warp.data();
  const Eigen::Vector4d& extent = shared ? in.board_extent : in.in_air_board_extent;
  VisitCameraModel(in.camera_model, [&](auto camera_tag) {
    using Functor = BoardReprojectionError<decltype(camera_tag)>;
    for (size_t v = 0; v < in.in_air->views.size(); ++v) {
      const CalibrationView& view = in.in_air->views[v];
      jp->air_ids.emplace_back();
      for (size_t i = 0; i < view.pixels.size(); ++i) {
        const Eigen::Vector3d& p = view.points_in_target[i];
        jp->air_ids.back().push_back(jp->problem.AddResidualBlock(
            Functor::Create(p, BoardWarpUv(p, extent), view.pixels[i]), loss,
            state->in_air_poses[v].data(), state->intrinsics.data(), warp));
      }
    }
  });
}

// What each block does in a solve: poses free; the housing refined unless
// `poses_only`; the intrinsics and the warp as `in` says, in the exact
// solve only (the virtual-camera error back-projects through the
// intrinsics, which is ill-conditioned far from the solution).
void SetBlocks(const Inputs& in, bool exact, bool poses_only, State* state,
               ceres::Problem* problem) {
  for (Pose& pose : state->poses) problem->SetManifold(pose.data(), PoseManifold());
  for (Pose& pose : state->in_air_poses) {
    if (problem->HasParameterBlock(pose.data())) problem->SetManifold(pose.data(), PoseManifold());
  }
  const bool intrinsics_free = exact && !poses_only && in.RefinesIntrinsics();
  const std::vector<int> fixed =
      in.in_air != nullptr ? in.in_air->fixed_params : std::vector<int>{};
  if (!intrinsics_free || fixed.size() == state->intrinsics.size()) {
    problem->SetParameterBlockConstant(state->intrinsics.data());
  } else if (!fixed.empty()) {
    problem->SetManifold(
        state->intrinsics.data(),
        new ceres::SubsetManifold(static_cast<int>(state->intrinsics.size()), fixed));
  }
  if (poses_only) {
    problem->SetParameterBlockConstant(state->housing.params.data());
  } else {
    SetHousingRefinement(state->housing, true, state->housing.params.data(), problem);
  }
  const bool warp_free = exact && !poses_only && in.settings.estimate_board_warp;
  for (double* warp : {state->warp.data(), state->in_air_warp.data()}) {
    if (problem->HasParameterBlock(warp) && !warp_free) problem->SetParameterBlockConstant(warp);
  }
}

// Solves poses only (housing and intrinsics fixed); returns the final cost.
double PoseOnlyCost(const Inputs& in, State* state) {
  JointProblem jp;
  AddWaterResiduals<PortErrorKind::kReprojection>(in, state, &jp);
  SetBlocks(in, true, true, state, &jp.problem);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 30;
  options.num_threads = in.settings.num_threads;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &jp.problem, &summary);
  return summary.IsSolutionUsable() ? summary.final_cost : 1e300;
}

// The start with the smallest pose-only residual among the model's
// candidates for the refraction axis the views show.
State BestStart(const Inputs& in, const State& state, const Eigen::Vector3d& axis) {
  double best_cost = 1e300;
  State best = state;
  for (const Housing& candidate : state.housing.StartCandidates(axis)) {
    State trial = state;
    trial.housing = candidate;
    const double cost = PoseOnlyCost(in, &trial);
    if (cost < best_cost) {
      best_cost = cost;
      best = trial;
    }
  }
  return best;
}

// Sum of squared residuals (unweighted) over `ids`; per view when asked.
double SumSquares(ceres::Problem* problem,
                  const std::vector<std::vector<ceres::ResidualBlockId>>& ids,
                  std::vector<double>* per_view_rms = nullptr) {
  double total = 0;
  for (const auto& view_ids : ids) {
    ceres::Problem::EvaluateOptions options;
    options.residual_blocks = view_ids;
    options.apply_loss_function = false;
    double cost = 0;
    problem->Evaluate(options, &cost, nullptr, nullptr, nullptr);
    total += 2 * cost;
    if (per_view_rms != nullptr)
      per_view_rms->push_back(std::sqrt(2 * cost / std::max<size_t>(1, view_ids.size())));
  }
  return total;
}

int NumPoints(const std::vector<CalibrationView>& views) {
  int n = 0;
  for (const CalibrationView& view : views) n += static_cast<int>(view.pixels.size());
  return n;
}

// Each set's residual variance (px^2), its own poses (and the housing, for
// the underwater set) taken from its degrees of freedom.
void WeighBySetVariance(const Inputs& in, JointProblem* jp, State* state) {
  const double water =
      SumSquares(&jp->problem, jp->water_ids) /
      std::max(1.0, 2.0 * NumPoints(in.views) - 6.0 * in.views.size() -
                        static_cast<double>(state->housing.Refinement().Refined().size()));
  const double air =
      SumSquares(&jp->problem, jp->air_ids) /
      std::max(1.0, 2.0 * NumPoints(in.in_air->views) - 6.0 * in.in_air->views.size());
  if (!(water > 0) || !(air > 0))
    throw NumericalError("housing calibration: a residual variance of zero");
  state->water_weight = 1 / water;
  state->air_weight = 1 / air;
  LOG(INFO) << "housing calibration: residual sigma " << std::sqrt(water) << " px under water, "
            << std::sqrt(air) << " px in air; each set weighted by it";
}

std::unique_ptr<JointProblem> SolveExactly(const Inputs& in, State* state) {
  auto jp = std::make_unique<JointProblem>();
  AddWaterResiduals<PortErrorKind::kReprojection>(in, state, jp.get());
  if (in.in_air != nullptr) AddAirResiduals(in, state, jp.get());
  SetBlocks(in, true, false, state, &jp->problem);
  SolveCalibration(&jp->problem, in.settings.max_num_iterations, in.settings.num_threads,
                   "housing calibration");
  return jp;
}

// Joint solves: virtual-camera error first (under water, intrinsics held),
// then the exact reprojection (with the in-air views: once, then again
// with each set weighted by its residual variance). Returns the final
// problem, for the covariance and the residuals.
std::unique_ptr<JointProblem> SolveJointly(const Inputs& in, State* state) {
  {
    JointProblem jp;
    AddWaterResiduals<PortErrorKind::kVirtualCamera>(in, state, &jp);
    SetBlocks(in, false, false, state, &jp.problem);
    SolveCalibration(&jp.problem, in.settings.max_num_iterations, in.settings.num_threads,
                     "housing calibration");
  }
  std::unique_ptr<JointProblem> jp = SolveExactly(in, state);
  if (in.in_air == nullptr) return jp;
  WeighBySetVariance(in, jp.get(), state);
  jp.reset();
  return SolveExactly(in, state);
}

// The free parameters of the final solve: the poses, the housing's refined
// ones (a unit vector has two), the intrinsics when refined, the warps.
int NumFreeParameters(const Inputs& in, const State& state) {
  const HousingRefinement refinement = state.housing.Refinement();
  int num_free = 6 * static_cast<int>(state.poses.size() + state.in_air_poses.size()) +
                 (refinement.orientation.empty() ? 0 : 2) +
                 static_cast<int>(refinement.position.size());
  if (in.RefinesIntrinsics()) {
    num_free += static_cast<int>(state.intrinsics.size()) -
                static_cast<int>(in.in_air != nullptr ? in.in_air->fixed_params.size() : 0);
  }
  if (in.settings.estimate_board_warp)
    num_free += (in.in_air != nullptr && !in.in_air->share_board_warp) ? 4 : 2;
  return num_free;
}

Eigen::MatrixXd CovarianceOf(ceres::Covariance* covariance, const double* block, int size,
                             double variance) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(size, size);
  covariance->GetCovarianceBlock(block, block, c.data());
  return c * variance;
}

std::vector<double> StdDevsOf(const Eigen::MatrixXd& covariance) {
  std::vector<double> std_dev(static_cast<size_t>(covariance.rows()));
  for (Eigen::Index i = 0; i < covariance.rows(); ++i) {
    std_dev[static_cast<size_t>(i)] = std::sqrt(std::max(0.0, covariance(i, i)));
  }
  return std_dev;
}

// Standard deviations from the covariance scaled by the (weighted)
// residual variance; -1 where the covariance is rank deficient.
void FillStdDevs(const Inputs& in, double variance, State* state, ceres::Problem* problem,
                 HousingCalibrationResult* result) {
  ceres::Covariance covariance(CalibrationCovarianceOptions(in.settings.num_threads));
  double* port = state->housing.params.data();
  std::vector<std::pair<const double*, const double*>> blocks = {{port, port}};
  if (in.RefinesIntrinsics())
    blocks.emplace_back(state->intrinsics.data(), state->intrinsics.data());
  if (in.settings.estimate_board_warp) blocks.emplace_back(state->warp.data(), state->warp.data());
  const bool own_air_warp =
      in.settings.estimate_board_warp && in.in_air != nullptr && !in.in_air->share_board_warp;
  if (own_air_warp) blocks.emplace_back(state->in_air_warp.data(), state->in_air_warp.data());
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
    if (in.RefinesIntrinsics())
      std::fill(result->camera_std_dev.begin(), result->camera_std_dev.end(), -1.0);
    return;
  }
  result->housing_covariance = CovarianceOf(&covariance, port, m, variance);
  if (in.lens_covariance != nullptr && !in.RefinesIntrinsics() && !refined.empty()) {
    // The held lens's own error, carried into the port (first order). If
    // that cannot be done, the report says the lens was taken as exact.
    try {
      result->housing_covariance += HeldBlockCovarianceContribution(
          problem, state->intrinsics.data(), *in.lens_covariance, port);
      result->lens_covariance_propagated = true;
    } catch (const NumericalError& e) {
      LOG(WARNING) << "housing calibration: the lens's covariance not propagated (" << e.what()
                   << ")";
    }
  }
  const std::vector<double> housing = StdDevsOf(result->housing_covariance);
  for (int k : refined)
    result->housing_std_dev[static_cast<size_t>(k)] = housing[static_cast<size_t>(k)];
  if (in.RefinesIntrinsics()) {
    result->camera_covariance = CovarianceOf(&covariance, state->intrinsics.data(), n, variance);
    result->camera_std_dev = StdDevsOf(result->camera_covariance);
  }
  if (in.settings.estimate_board_warp) {
    const std::vector<double> warp =
        StdDevsOf(CovarianceOf(&covariance, state->warp.data(), 2, variance));
    result->board_warp_std_dev = Eigen::Vector2d(warp[0], warp[1]);
  }
  if (own_air_warp) {
    const std::vector<double> warp =
        StdDevsOf(CovarianceOf(&covariance, state->in_air_warp.data(), 2, variance));
    result->in_air_board_warp_std_dev = Eigen::Vector2d(warp[0], warp[1]);
  }
}

std::vector<CalibratedView> ViewsOf(const std::vector<CalibrationView>& views,
                                    const std::vector<Pose>& poses,
                                    const std::vector<double>& rms) {
  std::vector<CalibratedView> out;
  for (size_t v = 0; v < views.size(); ++v) {
    CalibratedView view;
    view.image_name = views[v].image_name;
    view.num_points = static_cast<int>(views[v].pixels.size());
    view.cam_from_target = FromPose(poses[v]);
    view.rms_px = rms[v];
    out.push_back(view);
  }
  return out;
}

// The result at the solution: RMS and residual sigma of each set, the
// standard deviations, the per-view tables.
HousingCalibrationResult ResultOf(const Inputs& in, const Camera& camera, State* state,
                                  JointProblem* jp) {
  HousingCalibrationResult result;
  std::vector<double> water_rms, air_rms;
  const double water = SumSquares(&jp->problem, jp->water_ids, &water_rms);
  const double air = SumSquares(&jp->problem, jp->air_ids, &air_rms);
  const int num_points = NumPoints(in.views);
  const int num_air_points = in.in_air != nullptr ? NumPoints(in.in_air->views) : 0;
  const double dof = 2.0 * (num_points + num_air_points) - NumFreeParameters(in, *state);
  // Weighted: ~1 when each set's weight is its residual variance.
  const double variance =
      dof > 0 ? (state->water_weight * water + state->air_weight * air) / dof : 0;
  FillStdDevs(in, variance, state, &jp->problem, &result);
  result.housing = state->housing;
  result.camera = camera;
  result.camera.params = state->intrinsics;
  result.num_points = num_points;
  result.overall_rms_px = std::sqrt(water / std::max(1, num_points));
  result.residual_sigma_px = std::sqrt(variance / state->water_weight);
  result.views = ViewsOf(in.views, state->poses, water_rms);
  result.board_warp_estimated = in.settings.estimate_board_warp;
  result.board_warp = Eigen::Vector2d(state->warp[0], state->warp[1]);
  if (in.in_air != nullptr) {
    result.in_air_views = ViewsOf(in.in_air->views, state->in_air_poses, air_rms);
    result.in_air_rms_px = std::sqrt(air / std::max(1, num_air_points));
    result.in_air_residual_sigma_px = std::sqrt(variance / state->air_weight);
    if (in.settings.estimate_board_warp && !in.in_air->share_board_warp) {
      result.in_air_board_warp = Eigen::Vector2d(state->in_air_warp[0], state->in_air_warp[1]);
    }
  }
  return result;
}

}  // namespace

HousingCalibrationResult CalibrateHousing(const std::vector<CalibrationView>& views,
                                          const Camera& camera, const Housing& housing,
                                          const HousingCalibrationSettings& settings,
                                          const InAirViews* in_air,
                                          const Eigen::MatrixXd* lens_covariance) {
  settings.Check();
  camera.Validate("camera");
  housing.Validate("housing");
  const Eigen::Index n = static_cast<Eigen::Index>(camera.params.size());
  if (lens_covariance != nullptr && (lens_covariance->rows() != n || lens_covariance->cols() != n ||
                                     !lens_covariance->allFinite())) {
    throw InputError("housing calibration: the lens covariance is not " + std::to_string(n) +
                     " x " + std::to_string(n) + " finite numbers (" + camera.ModelName() + ")");
  }
  if (views.size() < 2) throw NumericalError("housing calibration needs at least 2 views");
  if (in_air != nullptr && in_air->views.empty())
    throw NumericalError("housing calibration: no in-air views");
  const Inputs in{views,
                  in_air,
                  camera.model_id,
                  SharedBoardExtent(views, in_air),
                  in_air != nullptr ? BoardExtent(in_air->views) : Eigen::Vector4d::Zero(),
                  settings,
                  lens_covariance};
  State state;
  state.intrinsics = camera.params;
  state.housing = housing;
  state.poses = InitialPoses(views, camera);
  if (in_air != nullptr) state.in_air_poses = InitialPoses(in_air->views, camera);

  const Eigen::Vector3d axis = EstimateAxis(views, camera);
  if (settings.initialize_from_data) {
    state = BestStart(in, state, axis);
    LOG(INFO) << "housing_calibrator: axis from the views " << axis.transpose() << ", start "
              << Eigen::Map<const Eigen::VectorXd>(
                     state.housing.params.data(),
                     static_cast<Eigen::Index>(state.housing.params.size()))
                     .transpose();
  }
  const std::unique_ptr<JointProblem> jp = SolveJointly(in, &state);
  state.housing.Validate("calibrated housing");
  HousingCalibrationResult result = ResultOf(in, camera, &state, jp.get());
  result.initial_axis = axis;
  return result;
}

}  // namespace portcal
