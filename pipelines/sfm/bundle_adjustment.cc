#include "pipelines/sfm/bundle_adjustment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/calibration/view_pose.h"
#include "pipelines/sfm/bundle_costs.h"
#include "pipelines/sfm/bundle_costs_fixed.h"
#include "pipelines/sfm/calibration_covariance.h"
#include "pipelines/sfm/position_priors.h"
#include "pipelines/sfm/ray_geometry.h"

namespace portcal {

void BundleAdjustmentOptions::Check() const {
  if (!(sigma_px > 0)) throw OptionError("--BundleAdjustment.sigma_px", std::to_string(sigma_px), "> 0");
  if (max_num_iterations < 1) {
    throw OptionError("--BundleAdjustment.max_num_iterations", std::to_string(max_num_iterations), ">= 1");
  }
  if (!(loss_scale >= 0)) throw OptionError("--BundleAdjustment.loss_scale", std::to_string(loss_scale), ">= 0");
  if (!(position_prior_sigma_m >= 0)) {
    throw OptionError("--PosePrior.position_sigma", std::to_string(position_prior_sigma_m), ">= 0 m");
  }
  if (!(function_tolerance > 0)) {
    throw OptionError("--BundleAdjustment.function_tolerance", std::to_string(function_tolerance), "> 0");
  }
}

BundleAdjustmentOptions BundleAdjustmentOptions::WithIntrinsicsHeld() const {
  BundleAdjustmentOptions held = *this;
  held.refine_focal_length = held.refine_principal_point = held.refine_extra_params = false;
  return held;
}

bool ImplausibleIntrinsics(const Camera& before, const Camera& after, std::string* why) {
  std::ostringstream text;
  const double ratio = after.MeanFocalLength() / before.MeanFocalLength();
  if (!(ratio > 0.5 && ratio < 2.0)) {
    text << "focal length " << after.MeanFocalLength() << " px from " << before.MeanFocalLength() << " px";
  }
  const std::vector<std::string> names = SplitTokens(after.ParamsInfo(), ", ");
  for (int idx : CameraModelExtraParamsIdxs(after.model_id)) {
    if (!(std::abs(after.params[idx]) < 1.0)) {
      text << (text.tellp() > 0 ? ", " : "") << names.at(idx) << " = " << after.params[idx];
    }
  }
  if (why) *why = text.str();
  return text.tellp() > 0;
}

std::vector<MarkerCorner> TriangulateMarkerCorners(const Reconstruction& reconstruction, double max_error_px) {
  std::map<std::pair<int, int>, MarkerCorner> corners;
  for (const auto& [image_id, pose] : reconstruction.poses()) {
    for (const MarkerDetection& m : reconstruction.inputs().images.at(image_id).markers) {
      for (int c = 0; c < 4; ++c) {
        MarkerCorner& corner = corners[{m.marker_id, c}];
        corner.marker_id = m.marker_id;
        corner.corner = c;
        corner.observations.emplace_back(image_id, m.corners[c]);
      }
    }
  }
  std::vector<MarkerCorner> result;
  for (auto& [key, corner] : corners) {
    if (corner.observations.size() < 2) continue;
    std::vector<Ray3d> rays;
    for (const auto& [image_id, pixel] : corner.observations) {
      const HousedCamera& camera = reconstruction.CameraOf(image_id);
      const auto ray = camera.Unproject(pixel);
      if (ray) rays.push_back(RayInWorld(*ray, reconstruction.poses().at(image_id)));
    }
    const auto xyz = TriangulateRays(rays);
    if (!xyz) continue;
    // Drop observations that disagree (a marker id seen twice, a bad corner).
    std::vector<std::pair<image_t, Eigen::Vector2d>> kept;
    for (const auto& [image_id, pixel] : corner.observations) {
      const HousedCamera& camera = reconstruction.CameraOf(image_id);
      const auto projected = camera.Project(reconstruction.poses().at(image_id) * *xyz);
      if (projected && (*projected - pixel).norm() < max_error_px) kept.emplace_back(image_id, pixel);
    }
    if (kept.size() < 2) continue;
    corner.observations = kept;
    corner.xyz = *xyz;
    result.push_back(corner);
  }
  return result;
}

namespace {

// Keypoints up to this scale (pixels) get sigma_px; coarser ones more.
constexpr double kReferenceScale = 2.0;

// |a - b| = length, in units of sigma.
struct DistanceError {
  DistanceError(double length, double sigma) : length_(length), inv_sigma_(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const T dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    residual[0] = (ceres::sqrt(dx * dx + dy * dy + dz * dz) - T(length_)) * T(inv_sigma_);
    return true;
  }
  double length_, inv_sigma_;
};

// Beyond a thousand free poses the reduced camera system is factorised
// sparsely only while it has at most this many 6x6 blocks (a survey's
// images each see a few dozen neighbours: 5000 images x 40); more, it is
// solved by preconditioned conjugate gradients.
constexpr size_t kMaxSparseSchurBlocks = 200000;

// The 6x6 blocks of the reduced camera system (the points eliminated): one
// per free image and one per ordered pair of free images that see a common
// point.
size_t ReducedCameraSystemBlocks(const Reconstruction& reconstruction,
                                 const std::map<point3D_t, Eigen::Vector3d>& point_blocks,
                                 const std::function<bool(image_t)>& is_free) {
  std::map<image_t, std::vector<image_t>> neighbours;
  std::vector<image_t> track;
  for (const auto& [point_id, xyz] : point_blocks) {
    track.clear();
    for (const TrackElement& e : reconstruction.points().at(point_id).track) {
      if (is_free(e.image_id)) track.push_back(e.image_id);
    }
    for (const image_t a : track) {
      std::vector<image_t>& of_a = neighbours[a];
      for (const image_t b : track) {
        if (b != a) of_a.push_back(b);
      }
    }
  }
  size_t blocks = 0;
  for (auto& [image_id, of_image] : neighbours) {
    std::sort(of_image.begin(), of_image.end());
    blocks += 1 + static_cast<size_t>(std::unique(of_image.begin(), of_image.end()) - of_image.begin());
  }
  return blocks;
}

// The parameter indices of a camera that stay constant.
std::vector<int> ConstantIntrinsics(const Camera& camera, const BundleAdjustmentOptions& o) {
  std::vector<int> constant;
  const auto add = [&](const std::vector<int>& idxs) { constant.insert(constant.end(), idxs.begin(), idxs.end()); };
  if (!o.refine_focal_length) add(CameraModelFocalLengthIdxs(camera.model_id));
  if (!o.refine_principal_point) add(CameraModelPrincipalPointIdxs(camera.model_id));
  const std::vector<int> extra = CameraModelExtraParamsIdxs(camera.model_id);
  if (!o.refine_extra_params) {
    add(extra);
  } else if (o.max_num_extra_params >= 0 && static_cast<size_t>(o.max_num_extra_params) < extra.size()) {
    add(std::vector<int>(extra.begin() + o.max_num_extra_params, extra.end()));
  }
  return constant;
}

// What the housing's model lets an adjustment refine (HousingRefinement):
// its orientation on the sphere, its position within the bounds, the rest
// held.
void SetHousingRefinement(const Housing& model, bool refine_position, double* housing, ceres::Problem* problem) {
  const HousingRefinement refinement = model.Refinement();
  const int n = static_cast<int>(model.params.size());
  std::vector<bool> refined(static_cast<size_t>(n), false);
  for (int k : refinement.orientation) refined[static_cast<size_t>(k)] = true;
  if (refine_position) {
    for (int k : refinement.position) refined[static_cast<size_t>(k)] = true;
  }
  if (std::none_of(refined.begin(), refined.end(), [](bool r) { return r; })) {
    problem->SetParameterBlockConstant(housing);
    return;
  }
  if (refinement.orientation.empty()) {
    std::vector<int> held;
    for (int k = 0; k < n; ++k) {
      if (!refined[static_cast<size_t>(k)]) held.push_back(k);
    }
    problem->SetManifold(housing, new ceres::SubsetManifold(n, held));
  } else {
    // The unit vector leads the parameters (every port model with one).
    PORTCAL_CHECK(refinement.orientation == (std::vector<int>{0, 1, 2}));
    std::vector<int> held;
    for (int k = 3; k < n; ++k) {
      if (!refined[static_cast<size_t>(k)]) held.push_back(k - 3);
    }
    problem->SetManifold(housing, new ceres::ProductManifold<ceres::SphereManifold<3>, ceres::SubsetManifold>(
                                      ceres::SphereManifold<3>(), ceres::SubsetManifold(n - 3, held)));
  }
  for (const HousingParamBound& bound : refinement.bounds) {
    if (std::isfinite(bound.lower)) problem->SetParameterLowerBound(housing, bound.index, bound.lower);
    if (std::isfinite(bound.upper)) problem->SetParameterUpperBound(housing, bound.index, bound.upper);
  }
}

}  // namespace

camera_t CameraWithHousingAtBound(const std::map<camera_t, HousedCamera>& cameras) {
  for (const auto& [id, camera] : cameras) {
    if (camera.housing && camera.housing->AtBound()) return id;
  }
  return kInvalidCameraId;
}

ceres::Solver::Summary AdjustBundle(Reconstruction* reconstruction, const BundleAdjustmentOptions& options,
                                    const BundleAdjustmentScope& scope, std::vector<MarkerCorner>* markers,
                                    const MarkerScale& marker_scale, CalibrationStdDevs* std_devs) {
  options.Check();
  std::map<image_t, Rigid3d>& poses = reconstruction->mutable_poses();
  PORTCAL_CHECK(poses.size() >= 2);
  std::map<image_t, PoseBlock> pose_blocks;
  for (const auto& [id, pose] : poses) pose_blocks[id] = ToPose(pose);
  std::map<camera_t, HousedCamera>& cameras = reconstruction->mutable_cameras();
  std::map<camera_t, std::vector<double>> intrinsics, housings;
  for (auto& [id, camera] : cameras) {
    intrinsics[id] = camera.camera.params;
    if (camera.housing) housings[id] = camera.housing->params;
  }

  // One loss object shared by the residuals; the problem deletes it once.
  ceres::Problem problem;
  ceres::LossFunction* loss = options.loss_scale > 0 ? new ceres::CauchyLoss(options.loss_scale) : nullptr;

  const bool local = !scope.variable_images.empty();
  const auto is_variable = [&](image_t id) { return !local || scope.variable_images.count(id) > 0; };
  std::map<point3D_t, Eigen::Vector3d> point_blocks;
  std::set<camera_t> used_cameras;
  int64_t num_residuals = 0;
  // Which blocks the residuals carry: constants are captured instead (see
  // bundle_costs.h), which makes the autodiff Jets much narrower.
  const bool refine_intrinsics =
      !local && (options.refine_focal_length || options.refine_principal_point || options.refine_extra_params);
  const bool refine_housing = !local && options.refine_housing;
  const auto blocks_of = [&](const HousedCamera& camera) {
    if (refine_housing && camera.housing) {
      return refine_intrinsics || options.virtual_camera_error ? CostBlocks::kAll : CostBlocks::kPosePointHousing;
    }
    if (refine_intrinsics || (options.virtual_camera_error && camera.housing)) {
      return camera.housing && options.virtual_camera_error ? CostBlocks::kAll : CostBlocks::kPosePointIntrinsics;
    }
    return CostBlocks::kPosePoint;
  };
  const auto add_observation = [&](image_t image_id, const Eigen::Vector2d& pixel, double* xyz, double sigma) {
    const SfmImage& image = reconstruction->inputs().images.at(image_id);
    const HousedCamera& camera = cameras.at(image.camera_id);
    ObservationModel model;
    model.camera_model_id = camera.camera.model_id;
    model.intrinsics = camera.camera.params;
    if (camera.housing) {
      model.housing_model_id = camera.housing->model_id;
      model.housing = camera.housing->params;
    }
    const CostBlocks kind = blocks_of(camera);
    ceres::CostFunction* cost =
        options.virtual_camera_error && camera.housing
            ? CreateVirtualCameraCost(camera.camera.model_id, camera.housing->model_id, pixel, sigma)
            : CreateReprojectionCost(model, kind, pixel, sigma);
    std::vector<double*> blocks = {pose_blocks.at(image_id).data(), xyz};
    if (kind == CostBlocks::kPosePointIntrinsics || kind == CostBlocks::kAll) {
      blocks.push_back(intrinsics.at(image.camera_id).data());
    }
    if ((kind == CostBlocks::kAll || kind == CostBlocks::kPosePointHousing) && camera.housing) {
      blocks.push_back(housings.at(image.camera_id).data());
    }
    problem.AddResidualBlock(cost, loss, blocks);
    used_cameras.insert(image.camera_id);
    num_residuals += 2;
  };

  // Points: those seen by a variable image (all, in a global adjustment).
  for (const auto& [point_id, point] : reconstruction->points()) {
    bool seen_by_variable = !local;
    for (const TrackElement& e : point.track) seen_by_variable |= is_variable(e.image_id);
    if (!seen_by_variable) continue;
    point_blocks[point_id] = point.xyz;
  }
  // A keypoint found at a coarse scale is located less precisely: SIFT's
  // localisation error grows with the feature's scale (measured on the
  // shared renders: median reprojection error 0.14 px below scale 2,
  // 0.49 px at 5-8, 0.89 px beyond 15), and behind a port it is also
  // biased, because refraction distorts a coarse blob unevenly. Sigma
  // growing with the square of the scale (above 2 px) measured best:
  // flat-port normal error 0.145 -> 0.085 (linear) -> 0.06 deg, dome
  // decentering 1.6 -> 0.15 -> 0.10 mm (with the exact error).
  const auto sigma_of = [&](const TrackElement& e) {
    const SfmImage& image = reconstruction->inputs().images.at(e.image_id);
    if (!options.scale_weighting || image.scales.empty()) return options.sigma_px;
    const double r = std::max(1.0, static_cast<double>(image.scales[e.point2D_idx]) / kReferenceScale);
    return options.sigma_px * r * r;
  };
  for (auto& [point_id, xyz] : point_blocks) {
    for (const TrackElement& e : reconstruction->points().at(point_id).track) {
      const HousedCamera& camera = reconstruction->CameraOf(e.image_id);
      const double sigma = sigma_of(e);
      const auto& ray = reconstruction->RayOf(e.image_id, e.point2D_idx);
      if (blocks_of(camera) == CostBlocks::kPosePoint && ray && ray->direction.z() > 1e-6) {
        // Intrinsics and housing held: the cheap fixed-ray error.
        problem.AddResidualBlock(CreateFixedRayCost(VirtualCenterOf(camera, *ray), ray->direction,
                                                    camera.camera.MeanFocalLength(), sigma),
                                 loss, pose_blocks.at(e.image_id).data(), xyz.data());
        num_residuals += 2;
        continue;
      }
      add_observation(e.image_id, reconstruction->inputs().images.at(e.image_id).keypoints[e.point2D_idx],
                      xyz.data(), sigma);
    }
  }
  const bool use_markers = markers && marker_scale.side_length_m > 0 && !markers->empty();
  if (use_markers) {
    std::map<int, std::array<double*, 4>> corners_of;
    for (MarkerCorner& corner : *markers) {
      for (const auto& [image_id, pixel] : corner.observations) {
        if (poses.count(image_id)) add_observation(image_id, pixel, corner.xyz.data(), options.marker_sigma_px);
      }
      if (!corners_of.count(corner.marker_id)) corners_of[corner.marker_id] = {nullptr, nullptr, nullptr, nullptr};
      corners_of[corner.marker_id][corner.corner] = corner.xyz.data();
    }
    const double side = marker_scale.side_length_m;
    for (const auto& [id, c] : corners_of) {
      for (int a = 0; a < 4; ++a) {
        for (int b = a + 1; b < 4; ++b) {
          if (!c[a] || !c[b]) continue;
          const double length = (b - a == 2) ? side * std::sqrt(2.0) : side;
          problem.AddResidualBlock(new ceres::AutoDiffCostFunction<DistanceError, 1, 3, 3>(
                                       new DistanceError(length, marker_scale.sigma_m)),
                                   nullptr, c[a], c[b]);
        }
      }
    }
  }

  // Position priors: residuals on the camera centres, robust (a navigation
  // fix can jump) at 3 sigma.
  const bool use_priors = !local && options.position_prior_sigma_m > 0 &&
                          NumUsablePositionPriors(*reconstruction) > 0;
  if (use_priors) {
    for (auto& [id, block] : pose_blocks) {
      const auto& prior = reconstruction->inputs().images.at(id).position_prior;
      if (!prior || !problem.HasParameterBlock(block.data())) continue;
      problem.AddResidualBlock(CreatePositionPriorCost(*prior, options.position_prior_sigma_m),
                               new ceres::HuberLoss(3.0), block.data());
      num_residuals += 3;
    }
  }

  // Poses: manifold; constant outside the local scope; the gauge.
  // Gauge: the first registered image is held. The scale is held by the
  // markers, or by a second held image (a local adjustment's neighbours), or
  // else by one translation coordinate of another image -- left free, the
  // scale drifts (refraction observes it only weakly, and a wrong housing
  // guess pulls it towards infinity, where the port's offsets vanish).
  // (The first image that has residuals: one whose observations were all
  // filtered out would hold nothing.)
  image_t first = poses.begin()->first;
  for (const auto& [id, block] : pose_blocks) {
    if (problem.HasParameterBlock(block.data())) {
      first = id;
      break;
    }
  }
  int num_held = 0;
  image_t scale_image = first;
  for (const auto& [id, block] : pose_blocks) {
    if (!problem.HasParameterBlock(block.data())) continue;
    if (!is_variable(id) || id == first) {
      ++num_held;
    } else if (scale_image == first) {
      scale_image = id;
    }
  }
  const bool hold_scale = !use_priors && !use_markers && num_held < 2 && scale_image != first;
  for (auto& [id, block] : pose_blocks) {
    if (!problem.HasParameterBlock(block.data())) continue;
    if (!is_variable(id) || (id == first && !use_priors)) {
      problem.SetParameterBlockConstant(block.data());
      continue;
    }
    if (hold_scale && id == scale_image) {
      // Hold the largest translation coordinate: it fixes the scale.
      const Eigen::Vector3d t(block[4], block[5], block[6]);
      int k;
      t.cwiseAbs().maxCoeff(&k);
      problem.SetManifold(block.data(),
                          new ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::SubsetManifold>(
                              ceres::EigenQuaternionManifold(), ceres::SubsetManifold(3, {k})));
      continue;
    }
    problem.SetManifold(block.data(), PoseManifold());
  }
  // Intrinsics and housings.
  for (camera_t id : used_cameras) {
    const HousedCamera& camera = cameras.at(id);
    double* params = intrinsics.at(id).data();
    if (problem.HasParameterBlock(params)) {
      const std::vector<int> constant = local ? std::vector<int>() : ConstantIntrinsics(camera.camera, options);
      const int n = static_cast<int>(camera.camera.params.size());
      if (local || static_cast<int>(constant.size()) == n) {
        problem.SetParameterBlockConstant(params);
      } else if (!constant.empty()) {
        problem.SetManifold(params, new ceres::SubsetManifold(n, constant));
      }
    }
    if (!camera.housing || !problem.HasParameterBlock(housings.at(id).data())) continue;
    double* housing = housings.at(id).data();
    if (local || !options.refine_housing) {
      problem.SetParameterBlockConstant(housing);
    } else {
      SetHousingRefinement(*camera.housing, options.refine_housing_position, housing, &problem);
    }
  }

  ceres::Solver::Options solver;
  // COLMAP's choice by the number of free poses: the reduced camera system
  // is small and dense for a few dozen images, sparse for a survey's
  // hundreds (each image sees its neighbours only), and beyond a thousand
  // preconditioned conjugate gradients keep memory bounded -- unless, as on
  // a survey, the system stays sparse however many images there are. (On a
  // 120-image survey, one global adjustment at 114 images ran for over a
  // minute under iterative Schur; with sparse Schur the whole mapping took
  // 256 s.)
  const auto free_pose = [&](image_t id) {
    const auto it = pose_blocks.find(id);
    return it != pose_blocks.end() && problem.HasParameterBlock(it->second.data()) &&
           !problem.IsParameterBlockConstant(it->second.data());
  };
  int num_free_poses = 0;
  for (auto& [id, block] : pose_blocks) num_free_poses += free_pose(id);
  const bool sparse_available = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  if (num_free_poses <= 50) {
    solver.linear_solver_type = ceres::DENSE_SCHUR;
  } else if (sparse_available &&
             (num_free_poses <= 1000 ||
              ReducedCameraSystemBlocks(*reconstruction, point_blocks, free_pose) <= kMaxSparseSchurBlocks)) {
    solver.linear_solver_type = ceres::SPARSE_SCHUR;
    solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  } else {
    solver.linear_solver_type = ceres::ITERATIVE_SCHUR;
    solver.preconditioner_type = ceres::SCHUR_JACOBI;
  }
  // With bounds (a flat port's distance, a dome's decentering) Ceres 2.1's
  // trust region runs a projected Armijo line search on every step, and its
  // default cubic interpolation evaluates the gradient -- the full Jacobian
  // -- at the trial point: a second Jacobian per iteration (1000-image
  // survey refinement: 9 s of each 21 s iteration). Quadratic interpolation
  // needs the cost only.
  solver.line_search_interpolation_type = ceres::QUADRATIC;
  solver.max_num_iterations = options.max_num_iterations;
  solver.num_threads = options.num_threads;
  // Per-iteration lines (cost, step, time) in the debug log.
  solver.logging_type = VLOG_IS_ON(2) ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw NumericalError("bundle adjustment failed: " + summary.BriefReport());
  VLOG(1) << "bundle adjustment: " << num_free_poses << " free poses, " << point_blocks.size() << " points, "
          << num_residuals << " residuals, " << summary.iterations.size() << " iterations, "
          << summary.total_time_in_seconds << " s (" << summary.BriefReport() << ")";
  VLOG(2) << summary.FullReport();

  if (std_devs) {
    std_devs->num_residuals = num_residuals;
    const double dof = std::max<double>(1.0, summary.num_residuals_reduced - summary.num_effective_parameters_reduced);
    // sigma0^2 = sum of squared (sigma-normalised) residuals / dof, from the
    // unrobustified residuals.
    double sum_sq = 0;
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.apply_loss_function = false;
    std::vector<double> residuals;
    problem.Evaluate(evaluate, nullptr, &residuals, nullptr, nullptr);
    for (double r : residuals) sum_sq += r * r;
    std_devs->sigma0 = std::sqrt(sum_sq / dof) * options.sigma_px;
    const double scale = std::sqrt(sum_sq / dof);
    const auto is_free = [&](const double* block) {
      return problem.HasParameterBlock(block) && !problem.IsParameterBlockConstant(block);
    };
    std::vector<double*> points, others;
    std::vector<const double*> wanted;
    for (auto& [id, xyz] : point_blocks) {
      if (is_free(xyz.data())) points.push_back(xyz.data());
    }
    for (auto& [id, block] : pose_blocks) {
      if (is_free(block.data())) others.push_back(block.data());
    }
    if (use_markers) {
      for (MarkerCorner& corner : *markers) {
        if (is_free(corner.xyz.data())) others.push_back(corner.xyz.data());
      }
    }
    for (camera_t id : used_cameras) {
      if (is_free(intrinsics.at(id).data())) {
        others.push_back(intrinsics.at(id).data());
        wanted.push_back(intrinsics.at(id).data());
      }
      if (housings.count(id) && is_free(housings.at(id).data())) {
        others.push_back(housings.at(id).data());
        wanted.push_back(housings.at(id).data());
      }
    }
    const auto describe = [&](const double* block, int index) -> std::string {
      for (const auto& [id, b] : pose_blocks) {
        if (b.data() == block) {
          return "the pose of image '" + reconstruction->inputs().images.at(id).name + "' (tangent " +
                 std::to_string(index) + ")";
        }
      }
      for (const auto& [id, b] : intrinsics) {
        if (b.data() == block) return "an intrinsic parameter of camera " + std::to_string(id) + " (refined ones: " +
                                      cameras.at(id).camera.ParamsInfo() + ")";
      }
      for (const auto& [id, b] : housings) {
        if (b.data() == block) return "a housing parameter of camera " + std::to_string(id);
      }
      return "a marker corner";
    };
    if (!wanted.empty()) {
      ResidualClusters clusters;
      int image_index = 0;
      for (const auto& [id, block] : pose_blocks) clusters.image_of_block[block.data()] = image_index++;
      // The marginalised points are tracks by themselves; a marker's
      // corner, seen in several images, is one too.
      if (use_markers) {
        int corner_index = 0;
        for (MarkerCorner& corner : *markers) clusters.track_of_block[corner.xyz.data()] = corner_index++;
      }
      clusters.residuals_per_dof = summary.num_residuals_reduced / dof;
      const auto start = std::chrono::steady_clock::now();
      const MarginalCovariance marginal =
          ComputeMarginalCovariance(&problem, points, others, wanted, scale, describe, &clusters);
      LOG(INFO) << "bundle adjustment: covariance of " << others.size() << " pose and calibration blocks, "
                << points.size() << " points marginalised, clustered by " << marginal.num_clusters << " images and "
                << marginal.num_tracks << " tracks: "
                << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s";
      const auto larger = [](std::vector<double> by_noise, const std::vector<double>& by_clusters) {
        for (size_t i = 0; i < by_clusters.size() && i < by_noise.size(); ++i) {
          by_noise[i] = std::max(by_noise[i], by_clusters[i]);
        }
        return by_noise;
      };
      for (camera_t id : used_cameras) {
        const double* intrinsics_block = intrinsics.at(id).data();
        const bool free_intrinsics = marginal.offset.count(intrinsics_block) > 0;
        if (free_intrinsics) {
          std_devs->intrinsics_by_noise[id] = marginal.StdDevs(intrinsics_block);
          std_devs->intrinsics_by_clusters[id] = marginal.ClusteredStdDevs(intrinsics_block);
          std_devs->intrinsics[id] = larger(std_devs->intrinsics_by_noise[id], std_devs->intrinsics_by_clusters[id]);
        }
        if (!housings.count(id) || !marginal.offset.count(housings.at(id).data())) continue;
        const double* housing_block = housings.at(id).data();
        std_devs->housing_by_noise[id] = marginal.StdDevs(housing_block);
        std_devs->housing_by_clusters[id] = marginal.ClusteredStdDevs(housing_block);
        std_devs->housing[id] = larger(std_devs->housing_by_noise[id], std_devs->housing_by_clusters[id]);
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
  }

  for (auto& [id, block] : pose_blocks) poses[id] = FromPose(block);
  for (const auto& [point_id, xyz] : point_blocks) reconstruction->point(point_id).xyz = xyz;
  bool cameras_changed = false;
  for (auto& [id, camera] : cameras) {
    cameras_changed |= camera.camera.params != intrinsics.at(id);
    camera.camera.params = intrinsics.at(id);
    if (camera.housing) {
      cameras_changed |= camera.housing->params != housings.at(id);
      camera.housing->params = housings.at(id);
    }
  }
  if (cameras_changed) reconstruction->UpdateRays();
  return summary;
}

}  // namespace portcal
