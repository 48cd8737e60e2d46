// AdjustBundle (bundle_adjustment.h) as a problem builder: the residuals
// (observations, marker constraints, position priors), the gauge, what the
// calibration blocks refine, the solver's choice, the standard deviations
// and the write-back, each a method of BundleProblem.
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

// A residual's robust weight w, held: rho(s) = w s (a ScaledLoss without
// an inner loss), kept by the problem builder in bulk.
class HeldWeight final : public ceres::LossFunction {
 public:
  explicit HeldWeight(double weight) : weight_(weight) {}
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = weight_ * s;
    rho[1] = weight_;
    rho[2] = 0;
  }

 private:
  double weight_;
};

// The problem owns the cost functions; the losses are the builder's (see
// BundleProblem's members).
ceres::Problem::Options ProblemOptions() {
  ceres::Problem::Options options;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

class BundleProblem {
 public:
  BundleProblem(Reconstruction* reconstruction, const BundleAdjustmentOptions& options,
                const BundleAdjustmentScope& scope, std::vector<MarkerCorner>* markers,
                const MarkerScale& marker_scale)
      : reconstruction_(reconstruction),
        options_(options),
        scope_(scope),
        markers_(markers),
        marker_scale_(marker_scale),
        poses_(reconstruction->mutable_poses()),
        cameras_(reconstruction->mutable_cameras()) {
    PORTCAL_CHECK(poses_.size() >= 2);
    for (const auto& [id, pose] : poses_) pose_blocks_[id] = ToPose(pose);
    for (auto& [id, camera] : cameras_) {
      intrinsics_[id] = camera.camera.params;
      if (camera.housing) housings_[id] = camera.housing->params;
    }
    // One loss object shared by the residuals. With the weights held, each
    // residual gets its own weight instead and the robust loss only
    // computes them.
    if (options.loss_scale > 0 && options.hold_loss_weights) {
      weight_loss_ = std::make_unique<ceres::CauchyLoss>(options.loss_scale);
    } else if (options.loss_scale > 0) {
      loss_ = std::make_unique<ceres::CauchyLoss>(options.loss_scale);
    }
    local_ = !scope.variable_images.empty();
    // Which blocks the residuals carry: constants are captured instead (see
    // bundle_costs.h), which makes the autodiff Jets much narrower.
    refine_intrinsics_ = !local_ && (options.refine_focal_length ||
                                     options.refine_principal_point || options.refine_extra_params);
    refine_housing_ = !local_ && options.refine_housing;
  }

  void AddPoints();
  void AddMarkers();
  void AddPositionPriors();
  void SetGauge();
  void SetCalibrationBlocks();
  ceres::Solver::Summary Solve();
  void ComputeStdDevs(const ceres::Solver::Summary& summary, CalibrationStdDevs* std_devs);
  void WriteBack();

 private:
  bool IsVariable(image_t id) const { return !local_ || scope_.variable_images.count(id) > 0; }
  CostBlocks BlocksOf(const HousedCamera& camera) const;
  void AddObservation(image_t image_id, const Eigen::Vector2d& pixel, double* xyz, double sigma);
  void AddRobustResidual(ceres::CostFunction* cost, const std::vector<double*>& blocks);
  double SigmaOf(const TrackElement& e) const;
  bool FreePose(image_t id) const;
  ceres::Solver::Options SolverOptions(int* num_free_poses) const;
  std::string Describe(const double* block, int index) const;
  std::string DescribeResidual(const std::vector<double*>& blocks) const;
  void StoreStdDevs(const MarginalCovariance& marginal, CalibrationStdDevs* std_devs) const;

  Reconstruction* reconstruction_;
  const BundleAdjustmentOptions& options_;
  const BundleAdjustmentScope& scope_;
  std::vector<MarkerCorner>* markers_;
  const MarkerScale& marker_scale_;
  std::map<image_t, Rigid3d>& poses_;
  std::map<camera_t, HousedCamera>& cameras_;
  std::map<image_t, PoseBlock> pose_blocks_;
  std::map<camera_t, std::vector<double>> intrinsics_, housings_;
  std::map<point3D_t, Eigen::Vector3d> point_blocks_;
  std::set<camera_t> used_cameras_;
  // The losses outlive the problem, which does not own them. A held weight
  // is 16 bytes here; as a ScaledLoss owned by the problem it was an
  // allocation and an entry in Ceres' table of the losses it owns, several
  // times that per observation (docs/scale.md).
  std::unique_ptr<ceres::LossFunction> loss_;  // the robust loss, shared
  std::unique_ptr<ceres::LossFunction>
      weight_loss_;                      // with hold_loss_weights: the weights' robust loss
  std::deque<HeldWeight> held_weights_;  // with hold_loss_weights: one per residual block
  ceres::HuberLoss prior_loss_{3.0};     // position priors' (3 sigma)
  ceres::Problem problem_{ProblemOptions()};
  std::vector<ceres::ResidualBlockId>
      robust_blocks_;  // under loss_, with max_unsettled_weight_fraction
  bool local_ = false;
  bool refine_intrinsics_ = false;
  bool refine_housing_ = false;
  bool use_markers_ = false;
  bool use_priors_ = false;
  int64_t num_residuals_ = 0;
};

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
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem_, &summary);
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

// What a parameter block is, for the covariance's error messages.
std::string BundleProblem::Describe(const double* block, int index) const {
  for (const auto& [id, b] : pose_blocks_) {
    if (b.data() == block) {
      return "the pose of image '" + reconstruction_->inputs().images.at(id).name + "' (tangent " +
             std::to_string(index) + ")";
    }
  }
  for (const auto& [id, b] : intrinsics_) {
    if (b.data() == block)
      return "an intrinsic parameter of camera " + std::to_string(id) +
             " (refined ones: " + cameras_.at(id).camera.ParamsInfo() + ")";
  }
  for (const auto& [id, b] : housings_) {
    if (b.data() == block) return "a housing parameter of camera " + std::to_string(id);
  }
  return "a marker corner";
}

// A residual by its parameter blocks (see AddPoints, AddMarkers and
// AddPositionPriors for their order).
std::string BundleProblem::DescribeResidual(const std::vector<double*>& blocks) const {
  std::string image;
  for (const auto& [id, block] : pose_blocks_) {
    if (block.data() == blocks[0])
      image = "image '" + reconstruction_->inputs().images.at(id).name + "'";
  }
  if (image.empty()) return "a marker's side";
  if (blocks.size() == 1) return "the position prior of " + image;
  for (const auto& [id, xyz] : point_blocks_) {
    if (xyz.data() == blocks[1])
      return "the observation of 3D point " + std::to_string(id) + " in " + image;
  }
  return "the observation of a marker corner in " + image;
}

void BundleProblem::ComputeStdDevs(const ceres::Solver::Summary& summary,
                                   CalibrationStdDevs* std_devs) {
  std_devs->num_residuals = num_residuals_;
  const double dof = std::max<double>(
      1.0, summary.num_residuals_reduced - summary.num_effective_parameters_reduced);
  // sigma0^2 = sum of squared (sigma-normalised) residuals / dof, from the
  // unrobustified residuals.
  double sum_sq = 0;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  std::vector<double> residuals;
  problem_.Evaluate(evaluate, nullptr, &residuals, nullptr, nullptr);
  for (double r : residuals) sum_sq += r * r;
  std_devs->sigma0 = std::sqrt(sum_sq / dof) * options_.sigma_px;
  const double scale = std::sqrt(sum_sq / dof);
  const auto is_free = [&](const double* block) {
    return problem_.HasParameterBlock(block) && !problem_.IsParameterBlockConstant(block);
  };
  std::vector<double*> points, others;
  std::vector<const double*> wanted;
  for (auto& [id, xyz] : point_blocks_) {
    if (is_free(xyz.data())) points.push_back(xyz.data());
  }
  for (auto& [id, block] : pose_blocks_) {
    if (is_free(block.data())) others.push_back(block.data());
  }
  if (use_markers_) {
    for (MarkerCorner& corner : *markers_) {
      if (is_free(corner.xyz.data())) others.push_back(corner.xyz.data());
    }
  }
  for (camera_t id : used_cameras_) {
    if (is_free(intrinsics_.at(id).data())) {
      others.push_back(intrinsics_.at(id).data());
      wanted.push_back(intrinsics_.at(id).data());
    }
    if (housings_.count(id) && is_free(housings_.at(id).data())) {
      others.push_back(housings_.at(id).data());
      wanted.push_back(housings_.at(id).data());
    }
  }
  if (wanted.empty()) return;
  ResidualClusters clusters;
  int image_index = 0;
  for (const auto& [id, block] : pose_blocks_)
    clusters.image_of_block[block.data()] = image_index++;
  // The marginalised points are tracks by themselves; a marker's corner,
  // seen in several images, is one too.
  if (use_markers_) {
    int corner_index = 0;
    for (MarkerCorner& corner : *markers_)
      clusters.track_of_block[corner.xyz.data()] = corner_index++;
  }
  clusters.residuals_per_dof = summary.num_residuals_reduced / dof;
  const auto start = std::chrono::steady_clock::now();
  const auto describe = [this](const double* block, int index) { return Describe(block, index); };
  const MarginalCovariance marginal =
      ComputeMarginalCovariance(&problem_, points, others, wanted, scale, describe, &clusters,
                                /*max_dense_size=*/1200, options_.num_threads);
  LOG(INFO) << "bundle adjustment: covariance of " << others.size()
            << " pose and calibration blocks, " << points.size()
            << " points marginalised, clustered by " << marginal.num_clusters << " images and "
            << marginal.num_tracks << " tracks: "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s";
  StoreStdDevs(marginal, std_devs);
}

// Each camera's standard deviations, the larger of the noise's and the
// clusters' estimates, and the correlations of its intrinsics with its
// housing.
void BundleProblem::StoreStdDevs(const MarginalCovariance& marginal,
                                 CalibrationStdDevs* std_devs) const {
  const auto larger = [](std::vector<double> by_noise, const std::vector<double>& by_clusters) {
    for (size_t i = 0; i < by_clusters.size() && i < by_noise.size(); ++i) {
      by_noise[i] = std::max(by_noise[i], by_clusters[i]);
    }
    return by_noise;
  };
  for (camera_t id : used_cameras_) {
    const double* intrinsics_block = intrinsics_.at(id).data();
    const bool free_intrinsics = marginal.offset.count(intrinsics_block) > 0;
    if (free_intrinsics) {
      std_devs->intrinsics_by_noise[id] = marginal.StdDevs(intrinsics_block);
      std_devs->intrinsics_by_clusters[id] = marginal.ClusteredStdDevs(intrinsics_block);
      std_devs->intrinsics[id] =
          larger(std_devs->intrinsics_by_noise[id], std_devs->intrinsics_by_clusters[id]);
    }
    if (!housings_.count(id) || !marginal.offset.count(housings_.at(id).data())) continue;
    const double* housing_block = housings_.at(id).data();
    std_devs->housing_by_noise[id] = marginal.StdDevs(housing_block);
    std_devs->housing_by_clusters[id] = marginal.ClusteredStdDevs(housing_block);
    std_devs->housing[id] =
        larger(std_devs->housing_by_noise[id], std_devs->housing_by_clusters[id]);
    if (!free_intrinsics) continue;
    Eigen::MatrixXd& correlation = std_devs->intrinsics_housing_correlation[id];
    correlation.resize(marginal.size.at(intrinsics_block), marginal.size.at(housing_block));
    for (int i = 0; i < correlation.rows(); ++i) {
      for (int j = 0; j < correlation.cols(); ++j) {
        correlation(i, j) = marginal.Correlation(intrinsics_block, i, housing_block, j);
      }
    }
  }
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

}  // namespace

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
