#include "pipelines/sfm/incremental_mapper.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/flat_port.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"
#include "pipelines/bundle_adjustment/position_priors.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace portcal {
namespace {

constexpr double kDegree = M_PI / 180.0;

}  // namespace

void IncrementalMapper::BeginModel() {
  port_converged_ = false;
  marker_corners_.clear();
  failed_.clear();
}

void IncrementalMapper::EndModel(const Reconstruction& r) {
  for (const auto& [id, pose] : r.poses()) used_.insert(id);
}

bool IncrementalMapper::RegisterImage(Reconstruction* r, image_t image_id) {
  const bool registered = Register(r, image_id);
  if (registered) {
    failed_.clear();
  } else {
    failed_.insert(image_id);
  }
  return registered;
}

std::vector<image_t> IncrementalMapper::NextImages(const Reconstruction& r) const {
  // Unregistered images ranked by how many of their keypoints see a point
  // of the model (Schoenberger 2016 also weighs their spread; the count is
  // what matters most for success).
  std::vector<std::pair<int, image_t>> ranked;
  for (const auto& [id, image] : inputs_.images) {
    if (r.IsRegistered(id) || used_.count(id) || failed_.count(id)) continue;
    const int visible = r.NumVisiblePoints(id);
    if (visible >= options_.abs_pose_min_num_inliers) ranked.emplace_back(visible, id);
  }
  std::sort(ranked.rbegin(), ranked.rend());
  std::vector<image_t> next;
  for (const auto& [count, id] : ranked) next.push_back(id);
  return next;
}

bool IncrementalMapper::Register(Reconstruction* r, image_t image_id) {
  const SfmImage& image = inputs_.images.at(image_id);
  std::vector<Ray3d> rays;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::pair<point2D_t, point3D_t>> links;
  for (point2D_t k = 0; k < image.correspondences.size(); ++k) {
    const auto& ray = r->RayOf(image_id, k);
    if (!ray) continue;
    for (const Correspondence& c : image.correspondences[k]) {
      const point3D_t p = r->PointOf(c.image_id, c.point2D_idx);
      if (p == kInvalidPoint3DId) continue;
      rays.push_back(*ray);
      points.push_back(r->points().at(p).xyz);
      links.emplace_back(k, p);
      break;
    }
  }
  GeneralizedAbsolutePoseOptions pose_options;
  pose_options.max_angle_error_rad = options_.abs_pose_max_error_px / FocalOf(image_id);
  pose_options.min_num_inliers = options_.abs_pose_min_num_inliers;
  pose_options.random_seed = options_.random_seed;
  std::vector<char> inliers;
  const auto cam_from_world = EstimateGeneralizedAbsolutePose(rays, points, pose_options, &inliers);
  if (!cam_from_world) return false;

  // Pose-only refinement through the exact projection, robust loss.
  PoseBlock pose = ToPose(*cam_from_world);
  const HousedCamera& camera = r->CameraOf(image_id);
  const ObservationModel model = ObservationModel::Of(camera);
  std::vector<Eigen::Vector3d> fixed_points;
  fixed_points.reserve(links.size());
  ceres::Problem problem;
  ceres::LossFunction* loss = new ceres::CauchyLoss(1.0);
  for (size_t i = 0; i < links.size(); ++i) {
    if (!inliers[i]) continue;
    fixed_points.push_back(points[i]);
    const Ray3d& ray = rays[i];
    ceres::CostFunction* cost =
        ray.direction.z() > 1e-6 ? CreateFixedRayCost(VirtualCenterOf(camera, ray), ray.direction,
                                                      camera.camera.MeanFocalLength(), 1.0)
                                 : CreateReprojectionCost(model, CostBlocks::kPosePoint,
                                                          image.keypoints[links[i].first], 1.0);
    problem.AddResidualBlock(cost, loss, pose.data(), fixed_points.back().data());
    problem.SetParameterBlockConstant(fixed_points.back().data());
  }
  problem.SetManifold(pose.data(), PoseManifold());
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.logging_type = ceres::SILENT;
  solver.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  const Rigid3d refined = FromPose(pose);

  r->Register(image_id, refined);
  int added = 0;
  for (size_t i = 0; i < links.size(); ++i) {
    const auto& [k, p] = links[i];
    if (r->points().count(p) == 0 || r->PointOf(image_id, k) != kInvalidPoint3DId) continue;
    bool already = false;  // two keypoints of one image on one point
    for (const TrackElement& e : r->points().at(p).track) already |= e.image_id == image_id;
    if (already) continue;
    if (r->ReprojectionError(image_id, k, r->points().at(p).xyz) >
        options_.filter_max_reproj_error_px)
      continue;
    r->AddObservation(p, {image_id, k});
    ++added;
  }
  if (added < options_.abs_pose_min_num_inliers) {
    r->Deregister(image_id);
    return false;
  }
  VLOG(1) << "registered '" << image.name << "' with " << added << " points";
  return true;
}

int IncrementalMapper::Triangulate(Reconstruction* r, image_t image_id) {
  const SfmImage& image = inputs_.images.at(image_id);
  const double max_error = options_.filter_max_reproj_error_px;
  int created = 0;
  for (point2D_t k = 0; k < image.correspondences.size(); ++k) {
    if (r->PointOf(image_id, k) != kInvalidPoint3DId || !r->RayOf(image_id, k)) continue;
    // Continue a track if a corresponding keypoint has a point that
    // projects here.
    bool continued = false;
    for (const Correspondence& c : image.correspondences[k]) {
      const point3D_t p = r->PointOf(c.image_id, c.point2D_idx);
      if (p == kInvalidPoint3DId) continue;
      bool already = false;
      for (const TrackElement& e : r->points().at(p).track) already |= e.image_id == image_id;
      if (already || r->ReprojectionError(image_id, k, r->points().at(p).xyz) > max_error) continue;
      r->AddObservation(p, {image_id, k});
      continued = true;
      break;
    }
    if (continued) continue;
    std::vector<TrackElement> track = {{image_id, k}};
    std::vector<Ray3d> rays = {RayInWorld(*r->RayOf(image_id, k), r->poses().at(image_id))};
    std::set<image_t> images = {image_id};
    for (const Correspondence& c : image.correspondences[k]) {
      if (!r->IsRegistered(c.image_id) || images.count(c.image_id)) continue;
      if (r->PointOf(c.image_id, c.point2D_idx) != kInvalidPoint3DId) continue;
      const auto& ray = r->RayOf(c.image_id, c.point2D_idx);
      if (!ray) continue;
      track.push_back({c.image_id, c.point2D_idx});
      rays.push_back(RayInWorld(*ray, r->poses().at(c.image_id)));
      images.insert(c.image_id);
    }
    if (track.size() < 2) continue;
    const auto x = TriangulateRays(rays);
    if (!x || MaxTriangulationAngle(rays, *x) < options_.tri_min_angle_deg * kDegree) continue;
    std::vector<TrackElement> good;
    for (const TrackElement& e : track) {
      if (r->ReprojectionError(e.image_id, e.point2D_idx, *x) <= max_error) good.push_back(e);
    }
    if (good.size() < 2 || good[0].image_id != image_id) continue;
    r->AddPoint(*x, good);
    ++created;
  }
  return created;
}

int IncrementalMapper::Filter(Reconstruction* r, const std::set<image_t>* images) {
  int removed = 0;
  std::vector<point3D_t> ids;
  if (images) {
    ids = r->PointsSeenBy(*images);
  } else {
    for (const auto& [id, point] : r->points()) ids.push_back(id);
  }
  for (point3D_t id : ids) {
    if (!r->points().count(id)) continue;
    const std::vector<TrackElement> track = r->points().at(id).track;
    for (const TrackElement& e : track) {
      if (!r->points().count(id)) break;
      if (r->ReprojectionError(e.image_id, e.point2D_idx, r->points().at(id).xyz) >
          options_.filter_max_reproj_error_px) {
        r->DeleteObservation(e.image_id, e.point2D_idx);
        ++removed;
      }
    }
    if (!r->points().count(id)) continue;
    std::vector<Ray3d> rays;
    for (const TrackElement& e : r->points().at(id).track) {
      rays.push_back(RayInWorld(*r->RayOf(e.image_id, e.point2D_idx), r->poses().at(e.image_id)));
    }
    if (MaxTriangulationAngle(rays, r->points().at(id).xyz) <
        options_.filter_min_tri_angle_deg * kDegree) {
      removed += static_cast<int>(rays.size());
      r->DeletePoint(id);
    }
  }
  return removed;
}

void IncrementalMapper::LocalAdjust(Reconstruction* r, image_t image_id) {
  // The new image and the images sharing the most points with it.
  std::map<image_t, int> shared;
  for (point2D_t k = 0; k < inputs_.images.at(image_id).keypoints.size(); ++k) {
    const point3D_t p = r->PointOf(image_id, k);
    if (p == kInvalidPoint3DId) continue;
    for (const TrackElement& e : r->points().at(p).track) {
      if (e.image_id != image_id) ++shared[e.image_id];
    }
  }
  std::vector<std::pair<int, image_t>> ranked;
  for (const auto& [id, count] : shared) ranked.emplace_back(count, id);
  std::sort(ranked.rbegin(), ranked.rend());
  BundleAdjustmentScope scope;
  scope.variable_images.insert(image_id);
  for (size_t i = 0; i < ranked.size() && static_cast<int>(i) < options_.ba_local_num_images - 1;
       ++i) {
    scope.variable_images.insert(ranked[i].second);
  }
  // COLMAP's local adjustment budget: a few iterations refine a pose
  // that registration already placed well.
  BundleAdjustmentOptions ba;
  ba.max_num_iterations = std::min(25, options_.ba_max_num_iterations);
  ba.function_tolerance = 1e-6;
  ba.num_threads = options_.num_threads;
  AdjustBundle(r, ba, scope, nullptr, MarkerScale());
  Filter(r, &scope.variable_images);
}

GlobalAdjustmentOutcome IncrementalMapper::AdjustGlobally(Reconstruction* r, bool refine_intrinsics,
                                                          AdjustmentEnd end) {
  // Intrinsics from a handful of views are barely constrained: they are
  // refined from kMinImagesForIntrinsics images on, and a result that is
  // bogus (COLMAP's test: focal length off by more than a factor 2 from the
  // start, a distortion parameter beyond 1) is undone and the adjustment
  // repeated with the intrinsics held.
  const int num_images = static_cast<int>(r->poses().size());
  refine_intrinsics = refine_intrinsics && num_images >= kMinImagesForIntrinsics;
  BundleAdjustmentOptions ba =
      GlobalAdjustmentOptions(options_, num_images, refine_intrinsics, end);
  if (options_.position_prior_sigma_m > 0 && options_.marker_scale.side_length_m <= 0 &&
      AlignToPositionPriors(r, 5 * options_.position_prior_sigma_m)) {
    // The model in the priors' metric frame, the priors as residuals.
    ba.position_prior_sigma_m = options_.position_prior_sigma_m;
  }
  if (options_.marker_scale.side_length_m > 0) {
    PrepareMarkerCorners(r, options_.filter_max_reproj_error_px * 4,
                         options_.marker_scale.side_length_m, &marker_corners_);
  }
  std::vector<MarkerCorner>& markers = marker_corners_;  // this adjustment's, kept for the next
  const ModelSnapshot before = ModelSnapshot::Of(*r, markers);
  AdjustHousingFirst(r, ba, &markers);
  const ceres::Solver::Summary summary =
      AdjustBundle(r, ba, BundleAdjustmentScope(), &markers, options_.marker_scale);
  const bool implausible =
      refine_intrinsics &&
      BogusIntrinsics(before.cameras, r->cameras(), cameras_, options_.max_focal_ratio_to_start,
                      options_.guessed_focal_cameras);
  if (implausible) {
    // Said once with its numbers; the later ones only at --log_level debug.
    const std::string text = "refractive_mapper: intrinsics refined on " +
                             std::to_string(r->poses().size()) + " images came out implausible (" +
                             CalibrationText(*r, false) + " ); held for now";
    const bool first = num_implausible_said_++ == 0;
    LOG_IF(WARNING, first) << text << " (the next ones at --log_level debug)";
    VLOG_IF(1, !first) << text;
    before.Restore(r, &markers);
    ba = ba.WithIntrinsicsHeld();
    ba.refine_housing = false;
    AdjustBundle(r, ba, BundleAdjustmentScope(), &markers, options_.marker_scale);
  }
  if (ba.refine_housing && EndedOnItsCriterion(summary)) {
    port_converged_ = CameraWithHousingAtBound(r->cameras()) == kInvalidCameraId;
  }
  GlobalAdjustmentOutcome outcome;
  outcome.refined_intrinsics = refine_intrinsics;
  outcome.implausible = implausible;
  outcome.ba = ba;
  outcome.summary = summary;
  outcome.cameras_before = before.cameras;
  return outcome;
}

void IncrementalMapper::AdjustHousingFirst(Reconstruction* r, const BundleAdjustmentOptions& ba,
                                           std::vector<MarkerCorner>* markers) {
  if (ba.refine_housing && !port_converged_ && HasOrientedHousing(*r)) {
    // A flat port's normal first, its distance held, until one joint
    // adjustment has converged: from the untilted guess the joint solve
    // pushes the distance into its floor and then creeps along the normal
    // for the whole iteration budget (docs/benchmarks.md: the 120-image
    // survey with the port tilted 3 deg).
    BundleAdjustmentOptions normal_first = ba.WithIntrinsicsHeld();
    normal_first.refine_housing_position = false;
    AdjustBundle(r, normal_first, BundleAdjustmentScope(), markers, options_.marker_scale);
  }
  if (ba.refine_housing &&
      (ba.refine_focal_length || ba.refine_principal_point || ba.refine_extra_params)) {
    // The housing first, under the held intrinsics (see
    // RunRefractiveBundleAdjuster: jointly from a poor start, focal length
    // and port distance trade off).
    AdjustBundle(r, ba.WithIntrinsicsHeld(), BundleAdjustmentScope(), markers,
                 options_.marker_scale);
  }
}

}  // namespace portcal
