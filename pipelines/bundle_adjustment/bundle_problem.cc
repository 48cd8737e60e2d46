#include "pipelines/bundle_adjustment/bundle_problem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <functional>
#include <memory>
#include <set>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/distance_error.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/util/cancel_callback.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"
#include "pipelines/bundle_adjustment/calibration_covariance.h"
#include "pipelines/bundle_adjustment/position_priors.h"
#include "pipelines/bundle_adjustment/reduced_camera_system.h"
#include "pipelines/bundle_adjustment/unevaluable_residuals.h"
#include "pipelines/bundle_adjustment/weights_settled.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace portcal {

namespace {

// Keypoints up to this scale (pixels) get sigma_px; coarser ones more.
constexpr double kReferenceScale = 2.0;

// Beyond a thousand free poses the reduced camera system is factorised
// sparsely only while it has at most this many 6x6 blocks (a survey's
// images each see a few dozen neighbours: 5000 images x 40); more, it is
// solved by preconditioned conjugate gradients.
constexpr size_t kMaxSparseSchurBlocks = 200000;

// The parameter indices of a camera that stay constant.
std::vector<int> ConstantIntrinsics(const Camera& camera, const BundleAdjustmentOptions& o) {
  std::vector<int> constant;
  const auto add = [&](const std::vector<int>& idxs) {
    constant.insert(constant.end(), idxs.begin(), idxs.end());
  };
  if (!o.refine_focal_length) add(CameraModelFocalLengthIdxs(camera.model_id));
  if (!o.refine_principal_point) add(CameraModelPrincipalPointIdxs(camera.model_id));
  const std::vector<int> extra = CameraModelExtraParamsIdxs(camera.model_id);
  if (!o.refine_extra_params) {
    add(extra);
  } else if (o.max_num_extra_params >= 0 &&
             static_cast<size_t>(o.max_num_extra_params) < extra.size()) {
    add(std::vector<int>(extra.begin() + o.max_num_extra_params, extra.end()));
  }
  return constant;
}

}  // namespace

// The problem owns the cost functions; the losses are the builder's (see
// BundleProblem's members).
ceres::Problem::Options ProblemOptions() {
  ceres::Problem::Options options;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

CostBlocks BundleProblem::BlocksOf(const HousedCamera& camera) const {
  if (refine_housing_ && camera.housing) {
    return refine_intrinsics_ || options_.virtual_camera_error ? CostBlocks::kAll
                                                               : CostBlocks::kPosePointHousing;
  }
  if (refine_intrinsics_ || (options_.virtual_camera_error && camera.housing)) {
    return camera.housing && options_.virtual_camera_error ? CostBlocks::kAll
                                                           : CostBlocks::kPosePointIntrinsics;
  }
  return CostBlocks::kPosePoint;
}

void BundleProblem::AddObservation(image_t image_id, const Eigen::Vector2d& pixel, double* xyz,
                                   double sigma) {
  const SfmImage& image = reconstruction_->inputs().images.at(image_id);
  const HousedCamera& camera = cameras_.at(image.camera_id);
  const ObservationModel model = ObservationModel::Of(camera);
  const CostBlocks kind = BlocksOf(camera);
  ceres::CostFunction* cost =
      options_.virtual_camera_error && camera.housing
          ? CreateVirtualCameraCost(camera.camera.model_id, camera.housing->model_id, pixel, sigma)
          : CreateReprojectionCost(model, kind, pixel, sigma);
  std::vector<double*> blocks = {pose_blocks_.at(image_id).data(), xyz};
  if (kind == CostBlocks::kPosePointIntrinsics || kind == CostBlocks::kAll) {
    blocks.push_back(intrinsics_.at(image.camera_id).data());
  }
  if ((kind == CostBlocks::kAll || kind == CostBlocks::kPosePointHousing) && camera.housing) {
    blocks.push_back(housings_.at(image.camera_id).data());
  }
  AddRobustResidual(cost, blocks);
  used_cameras_.insert(image.camera_id);
}

// An observation's residual under the robust loss, or, with the weights
// held, under its weight rho'(|r|^2) at the current parameters (a residual
// that cannot be evaluated there gets weight 1: the solve then fails on it
// and says so).
void BundleProblem::AddRobustResidual(ceres::CostFunction* cost,
                                      const std::vector<double*>& blocks) {
  num_residuals_ += cost->num_residuals();
  if (!weight_loss_) {
    const ceres::ResidualBlockId id = problem_.AddResidualBlock(cost, loss_.get(), blocks);
    if (loss_ && options_.max_unsettled_weight_fraction > 0) robust_blocks_.push_back(id);
    return;
  }
  Eigen::VectorXd residual(cost->num_residuals());
  double rho[3] = {0, 1, 0};
  if (cost->Evaluate(blocks.data(), residual.data(), nullptr) && residual.allFinite()) {
    weight_loss_->Evaluate(residual.squaredNorm(), rho);
  }
  held_weights_.emplace_back(rho[1]);
  problem_.AddResidualBlock(cost, &held_weights_.back(), blocks);
}

// A keypoint found at a coarse scale is located less precisely: SIFT's
// localisation error grows with the feature's scale, and behind a port it
// is also biased, because refraction distorts a coarse blob unevenly.
// Sigma grows with the square of the scale above 2 px, which measured best
// (docs/dev/auto_calibration_notes.md).
double BundleProblem::SigmaOf(const TrackElement& e) const {
  const SfmImage& image = reconstruction_->inputs().images.at(e.image_id);
  if (!options_.scale_weighting || image.scales.empty()) return options_.sigma_px;
  const double r =
      std::max(1.0, static_cast<double>(image.scales[e.point2D_idx]) / kReferenceScale);
  return options_.sigma_px * r * r;
}

// Points: those seen by a variable image (all, in a global adjustment).
void BundleProblem::AddPoints() {
  if (local_) {
    for (const point3D_t point_id : reconstruction_->PointsSeenBy(scope_.variable_images)) {
      point_blocks_[point_id] = reconstruction_->points().at(point_id).xyz;
    }
  } else {
    for (const auto& [point_id, point] : reconstruction_->points())
      point_blocks_[point_id] = point.xyz;
  }
  for (auto& [point_id, xyz] : point_blocks_) {
    for (const TrackElement& e : reconstruction_->points().at(point_id).track) {
      const HousedCamera& camera = reconstruction_->CameraOf(e.image_id);
      const double sigma = SigmaOf(e);
      const auto& ray = reconstruction_->RayOf(e.image_id, e.point2D_idx);
      if (BlocksOf(camera) == CostBlocks::kPosePoint && ray && ray->direction.z() > 1e-6) {
        // Intrinsics and housing held: the cheap fixed-ray error.
        AddRobustResidual(CreateFixedRayCost(VirtualCenterOf(camera, *ray), ray->direction,
                                             camera.camera.MeanFocalLength(), sigma),
                          {pose_blocks_.at(e.image_id).data(), xyz.data()});
        continue;
      }
      AddObservation(e.image_id,
                     reconstruction_->inputs().images.at(e.image_id).keypoints[e.point2D_idx],
                     xyz.data(), sigma);
    }
  }
}

// The markers' corners, observed, and their sides of known length: the
// scale.
void BundleProblem::AddMarkers() {
  use_markers_ = markers_ && marker_scale_.side_length_m > 0 && !markers_->empty();
  if (!use_markers_) return;
  std::map<int, std::array<double*, 4>> corners_of;
  for (MarkerCorner& corner : *markers_) {
    for (const auto& [image_id, pixel] : corner.observations) {
      if (poses_.count(image_id))
        AddObservation(image_id, pixel, corner.xyz.data(), options_.marker_sigma_px);
    }
    if (!corners_of.count(corner.marker_id))
      corners_of[corner.marker_id] = {nullptr, nullptr, nullptr, nullptr};
    corners_of[corner.marker_id][corner.corner] = corner.xyz.data();
  }
  const double side = marker_scale_.side_length_m;
  for (const auto& [id, c] : corners_of) {
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        if (!c[a] || !c[b]) continue;
        const double length = (b - a == 2) ? side * std::sqrt(2.0) : side;
        problem_.AddResidualBlock(DistanceError::Create(length, marker_scale_.sigma_m), nullptr,
                                  c[a], c[b]);
      }
    }
  }
}

// Position priors: residuals on the camera centres, robust (a navigation
// fix can jump) at 3 sigma.
void BundleProblem::AddPositionPriors() {
  use_priors_ = !local_ && options_.position_prior_sigma_m > 0 &&
                NumUsablePositionPriors(*reconstruction_) > 0;
  if (!use_priors_) return;
  for (auto& [id, block] : pose_blocks_) {
    const auto& prior = reconstruction_->inputs().images.at(id).position_prior;
    if (!prior || !problem_.HasParameterBlock(block.data())) continue;
    problem_.AddResidualBlock(CreatePositionPriorCost(*prior, options_.position_prior_sigma_m),
                              &prior_loss_, block.data());
    num_residuals_ += 3;
  }
}

// Poses: manifold; constant outside the local scope; the gauge. The first
// registered image that has residuals is held. The scale is held by the
// markers, the priors, or a second held image (a local adjustment's
// neighbours), or else by one translation coordinate of another image --
// left free, the scale drifts (refraction observes it only weakly, and a
// wrong housing guess pulls it towards infinity, where the port's offsets
// vanish).
void BundleProblem::SetGauge() {
  image_t first = poses_.begin()->first;
  for (const auto& [id, block] : pose_blocks_) {
    if (problem_.HasParameterBlock(block.data())) {
      first = id;
      break;
    }
  }
  int num_held = 0;
  image_t scale_image = first;
  for (const auto& [id, block] : pose_blocks_) {
    if (!problem_.HasParameterBlock(block.data())) continue;
    if (!IsVariable(id) || id == first) {
      ++num_held;
    } else if (scale_image == first) {
      scale_image = id;
    }
  }
  const bool hold_scale = !use_priors_ && !use_markers_ && num_held < 2 && scale_image != first;
  for (auto& [id, block] : pose_blocks_) {
    if (!problem_.HasParameterBlock(block.data())) continue;
    if (!IsVariable(id) || (id == first && !use_priors_)) {
      problem_.SetParameterBlockConstant(block.data());
      continue;
    }
    if (hold_scale && id == scale_image) {
      // Hold the largest translation coordinate: it fixes the scale.
      const Eigen::Vector3d t(block[4], block[5], block[6]);
      int k;
      t.cwiseAbs().maxCoeff(&k);
      problem_.SetManifold(
          block.data(),
          new ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::SubsetManifold>(
              ceres::EigenQuaternionManifold(), ceres::SubsetManifold(3, {k})));
      continue;
    }
    problem_.SetManifold(block.data(), PoseManifold());
  }
}

// Intrinsics and housings: what the options refine, the rest held.
void BundleProblem::SetCalibrationBlocks() {
  for (camera_t id : used_cameras_) {
    const HousedCamera& camera = cameras_.at(id);
    double* params = intrinsics_.at(id).data();
    if (problem_.HasParameterBlock(params)) {
      const std::vector<int> constant =
          local_ ? std::vector<int>() : ConstantIntrinsics(camera.camera, options_);
      const int n = static_cast<int>(camera.camera.params.size());
      if (local_ || static_cast<int>(constant.size()) == n) {
        problem_.SetParameterBlockConstant(params);
      } else if (!constant.empty()) {
        problem_.SetManifold(params, new ceres::SubsetManifold(n, constant));
      }
    }
    if (!camera.housing || !problem_.HasParameterBlock(housings_.at(id).data())) continue;
    double* housing = housings_.at(id).data();
    if (local_ || !options_.refine_housing) {
      problem_.SetParameterBlockConstant(housing);
    } else {
      SetHousingRefinement(*camera.housing, options_.refine_housing_position, housing, &problem_);
    }
  }
}

bool BundleProblem::FreePose(image_t id) const {
  const auto it = pose_blocks_.find(id);
  return it != pose_blocks_.end() && problem_.HasParameterBlock(it->second.data()) &&
         !problem_.IsParameterBlockConstant(it->second.data());
}

// COLMAP's choice by the number of free poses: the reduced camera system is
// small and dense for a few dozen images, sparse for a survey's hundreds
// (each image sees its neighbours only), and beyond a thousand
// preconditioned conjugate gradients keep memory bounded -- unless, as on a
// survey, the system stays sparse however many images there are.
ceres::Solver::Options BundleProblem::SolverOptions(int* num_free_poses) const {
  ceres::Solver::Options solver;
  *num_free_poses = 0;
  for (const auto& [id, block] : pose_blocks_) *num_free_poses += FreePose(id);
  const bool sparse_available =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  const auto free_pose = [this](image_t id) { return FreePose(id); };
  if (*num_free_poses <= 50) {
    solver.linear_solver_type = ceres::DENSE_SCHUR;
  } else if (sparse_available && (*num_free_poses <= 1000 ||
                                  ReducedCameraSystemBlocks(*reconstruction_, point_blocks_,
                                                            free_pose) <= kMaxSparseSchurBlocks)) {
    solver.linear_solver_type = ceres::SPARSE_SCHUR;
    solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  } else {
    solver.linear_solver_type = ceres::ITERATIVE_SCHUR;
    solver.preconditioner_type = ceres::SCHUR_JACOBI;
  }
  // With bounds (a flat port's distance floor, a dome's decentering box)
  // Ceres 2.1's trust region runs a projected Armijo line search on every
  // step unless told not to. Where the full step is good it costs a cost
  // evaluation; where the step overshoots it shortens the step yet rates it
  // against the full step's predicted decrease, so a step that should be
  // rejected is accepted at a ratio of ~0.002 and Levenberg-Marquardt only
  // halves its region, at one Jacobian and one linear solve a halving
  // (a rejection shrinks it 2, 4, 8 ... times for a linear solve each;
  // docs/scale.md). The bounds hold without it: Ceres projects every
  // step's end onto them.
  solver.max_num_line_search_step_size_iterations = 0;
  solver.max_num_iterations = options_.max_num_iterations;
  solver.num_threads = options_.num_threads;
  // Per-iteration lines (cost, step, time) in the debug log.
  solver.logging_type = VLOG_IS_ON(2) ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  solver.function_tolerance = options_.function_tolerance;
  solver.initial_trust_region_radius = options_.initial_trust_region_radius;
  solver.parameter_tolerance = 1e-10;
  return solver;
}

ceres::Solver::Summary BundleProblem::Solve() {
  int num_free_poses = 0;
  ceres::Solver::Options solver = SolverOptions(&num_free_poses);
  std::unique_ptr<WeightsSettledCallback> weights_settled;
  if (!robust_blocks_.empty()) {
    weights_settled = std::make_unique<WeightsSettledCallback>(
        &problem_, std::move(robust_blocks_), loss_.get(), options_.max_unsettled_weight_fraction);
    solver.callbacks.push_back(weights_settled.get());
    solver.update_state_every_iteration = true;
  }
  CancelCallback cancel;
  solver.callbacks.push_back(&cancel);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem_, &summary);
  CancelFlag::ThrowIfRequested();  // an abort on SIGINT is no failed solve
  if (!summary.IsSolutionUsable()) {
    throw NumericalError(
        "bundle adjustment failed: " + summary.BriefReport() +
        DescribeUnevaluableResiduals(problem_, [this](const std::vector<double*>& blocks) {
          return DescribeResidual(blocks);
        }));
  }
  VLOG(1) << "bundle adjustment: " << num_free_poses << " free poses, " << point_blocks_.size()
          << " points, " << num_residuals_ << " residuals, " << summary.iterations.size()
          << " iterations, " << summary.total_time_in_seconds << " s (" << summary.BriefReport()
          << ")";
  VLOG(2) << summary.FullReport();
  return summary;
}

void BundleProblem::WriteBack() {
  for (auto& [id, block] : pose_blocks_) poses_[id] = FromPose(block);
  for (const auto& [point_id, xyz] : point_blocks_) reconstruction_->point(point_id).xyz = xyz;
  bool cameras_changed = false;
  for (auto& [id, camera] : cameras_) {
    cameras_changed |= camera.camera.params != intrinsics_.at(id);
    camera.camera.params = intrinsics_.at(id);
    if (camera.housing) {
      cameras_changed |= camera.housing->params != housings_.at(id);
      camera.housing->params = housings_.at(id);
    }
  }
  if (cameras_changed) reconstruction_->UpdateRays();
}

ceres::Solver::Summary AdjustBundle(Reconstruction* reconstruction,
                                    const BundleAdjustmentOptions& options,
                                    const BundleAdjustmentScope& scope,
                                    std::vector<MarkerCorner>* markers,
                                    const MarkerScale& marker_scale, CalibrationStdDevs* std_devs) {
  options.Check();
  BundleProblem problem(reconstruction, options, scope, markers, marker_scale);
  problem.AddPoints();
  problem.AddMarkers();
  problem.AddPositionPriors();
  problem.SetGauge();
  problem.SetCalibrationBlocks();
  const ceres::Solver::Summary summary = problem.Solve();
  if (std_devs) problem.ComputeStdDevs(summary, std_devs);
  problem.WriteBack();
  return summary;
}

}  // namespace portcal
