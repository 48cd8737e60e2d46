#include "pipelines/sfm/incremental_mapper.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/flat_port.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/bundle_costs_fixed.h"
#include "pipelines/bundle_adjustment/position_priors.h"
#include "pipelines/reconstruction/ray_geometry.h"
#include "pipelines/sfm/camera_change.h"
#include "pipelines/sfm/global_adjustment.h"
#include "pipelines/sfm/initial_pair.h"

namespace portcal {

void IncrementalMapperOptions::Check() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0)) throw OptionError(std::string("--Mapper.") + name, std::to_string(v), "> 0");
  };
  positive(init_min_num_inliers, "init_min_num_inliers");
  positive(init_max_error_px, "init_max_error");
  positive(init_scene_depth_m, "init_scene_depth");
  positive(abs_pose_max_error_px, "abs_pose_max_error");
  positive(filter_max_reproj_error_px, "filter_max_reproj_error");
  positive(ba_global_images_ratio, "ba_global_images_ratio");
  positive(max_num_models, "max_num_models");
  if (!(position_prior_sigma_m >= 0)) {
    throw OptionError("--PosePrior.position_sigma", std::to_string(position_prior_sigma_m),
                      ">= 0 m");
  }
  const auto angle = [](double v, const char* name) {
    if (!(v >= 0 && v < 90)) {
      throw OptionError(std::string("--Mapper.") + name, std::to_string(v), "in [0, 90) degrees");
    }
  };
  angle(init_min_tri_angle_deg, "init_min_tri_angle");
  angle(filter_min_tri_angle_deg, "filter_min_tri_angle");
  angle(tri_min_angle_deg, "tri_min_angle");
  marker_scale.Check();
  if (abs_pose_min_num_inliers < 6) {
    throw OptionError("--Mapper.abs_pose_min_num_inliers", std::to_string(abs_pose_min_num_inliers),
                      ">= 6");
  }
  if (!(max_focal_ratio_to_start > 1)) {
    throw OptionError("--Mapper.max_focal_ratio_to_start", std::to_string(max_focal_ratio_to_start),
                      "> 1");
  }
  if (random_seed < 0) throw OptionError("--random_seed", std::to_string(random_seed), ">= 0");
  if (init_max_restarts < 0)
    throw OptionError("--Mapper.init_max_restarts", std::to_string(init_max_restarts), ">= 0");
  if (min_model_size < 2)
    throw OptionError("--Mapper.min_model_size", std::to_string(min_model_size), ">= 2");
  if (ba_local_num_images < 1) {
    throw OptionError("--Mapper.ba_local_num_images", std::to_string(ba_local_num_images), ">= 1");
  }
  if (!(ba_global_function_tolerance > 0 && ba_global_function_tolerance < 1)) {
    throw OptionError("--Mapper.ba_global_function_tolerance",
                      std::to_string(ba_global_function_tolerance), "in (0, 1)");
  }
  if (!(ba_global_max_unsettled_weights >= 0 && ba_global_max_unsettled_weights < 1)) {
    throw OptionError("--Mapper.ba_global_max_unsettled_weights",
                      std::to_string(ba_global_max_unsettled_weights), "in [0, 1)");
  }
  if (!(ba_calibration_settled_px >= 0)) {
    throw OptionError("--Mapper.ba_calibration_settled_px",
                      std::to_string(ba_calibration_settled_px), ">= 0");
  }
  if (ba_full_intrinsics_min_images < 0) {
    throw OptionError("--Mapper.ba_full_intrinsics_min_images",
                      std::to_string(ba_full_intrinsics_min_images), ">= 0");
  }
  if (ba_calibration_settled_min_images < 2) {
    throw OptionError("--Mapper.ba_calibration_settled_min_images",
                      std::to_string(ba_calibration_settled_min_images), ">= 2");
  }
}

namespace {

constexpr double kDegree = M_PI / 180.0;

class Mapper {
 public:
  Mapper(const SfmInputs& inputs, const std::map<camera_t, HousedCamera>& cameras,
         const IncrementalMapperOptions& options)
      : inputs_(inputs), cameras_(cameras), options_(options) {}

  std::vector<MappedModel> Run(ProgressSink& progress);

 private:
  double FocalOf(image_t image_id) const {
    return cameras_.at(inputs_.images.at(image_id).camera_id).camera.MeanFocalLength();
  }
  // The pair it started from in `start`.
  bool Initialize(Reconstruction* r, std::set<image_pair_t>* tried, image_pair_t* start);
  bool TryInitialPair(Reconstruction* r, image_t a, image_t b);
  bool Register(Reconstruction* r, image_t image_id);
  int Triangulate(Reconstruction* r, image_t image_id);
  int Filter(Reconstruction* r, const std::set<image_t>* images);
  void LocalAdjust(Reconstruction* r, image_t image_id);
  void GlobalAdjust(Reconstruction* r, bool refine_intrinsics,
                    AdjustmentEnd end = AdjustmentEnd::kCostChange);
  // The housing's adjustments before the joint one (see GlobalAdjust).
  void AdjustHousingFirst(Reconstruction* r, const BundleAdjustmentOptions& ba,
                          std::vector<MarkerCorner>* markers);
  // Records a global adjustment's refinement of the calibration and whether
  // it has settled.
  void NoteRefinement(const Reconstruction& r, const BundleAdjustmentOptions& ba, bool implausible,
                      const ceres::Solver::Summary& summary,
                      const std::map<camera_t, HousedCamera>& cameras_before);
  // Clears what the mapper tracks about the model it grows.
  void StartModel();
  // Registers images one at a time, triangulating and adjusting, until none
  // registers or the model is abandoned.
  void GrowModel(Reconstruction* r, bool abandon_allowed, ProgressSink& progress);
  // Triangulates, adjusts and filters a grown model once more.
  void FinishModel(Reconstruction* r, size_t model_index);
  // The model's intrinsics came out implausible too often in a row (own
  // render: from 5 images on at every refinement): its start was likely wrong.
  bool Abandon(bool abandon_allowed) const {
    constexpr int kImplausibleInARowToAbandon = 3;
    return abandon_allowed && num_implausible_in_a_row_ >= kImplausibleInARowToAbandon;
  }
  std::vector<image_t> NextImages(const Reconstruction& r) const;

  const SfmInputs& inputs_;
  const std::map<camera_t, HousedCamera>& cameras_;
  const IncrementalMapperOptions& options_;
  std::set<image_t> used_;    // registered in an earlier model
  std::set<image_t> failed_;  // failed to register since the model last grew
  // A global adjustment refining the housing has converged (off its bounds) in the current model.
  bool port_converged_ = false;
  // The markers' corners as the last global adjustment left them.
  std::vector<MarkerCorner> marker_corners_;
  // How many global adjustments that refined the intrinsics found them
  // implausible (and held them) in a row, up to the last one.
  int num_implausible_in_a_row_ = 0;
  // How many global adjustments that refined the intrinsics or housing, on
  // at least ba_calibration_settled_min_images images, moved the image by
  // less than ba_calibration_settled_px in a row, up to the last one.
  int num_settled_in_a_row_ = 0;
  std::vector<CalibrationRefinement> refinements_;  // of the current model
  bool CalibrationSettled() const {
    return options_.ba_calibration_settled_px > 0 && num_settled_in_a_row_ >= 2;
  }
  // Seconds spent per step, for the debug log.
  std::map<std::string, double> seconds_;
  template <typename F>
  auto Timed(const char* step, F&& f) {
    const auto start = std::chrono::steady_clock::now();
    struct Add {
      std::map<std::string, double>* seconds;
      const char* step;
      std::chrono::steady_clock::time_point start;
      ~Add() {
        (*seconds)[step] +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
    } add{&seconds_, step, start};
    return f();
  }
};

std::vector<MappedModel> Mapper::Run(ProgressSink& progress) {
  std::vector<MappedModel> models;
  std::set<image_pair_t> tried = options_.init_excluded_pairs;
  progress.Begin("refractive_mapper: images registered", inputs_.images.size());
  // Initial pairs of the current model whose growth was abandoned because
  // the intrinsics kept coming out implausible (a wrong start, see
  // IncrementalMapperOptions::init_max_restarts). With no other pair left,
  // the first is built again to the end, its intrinsics held where
  // implausible, as before there were restarts.
  std::vector<image_pair_t> abandoned;
  bool may_abandon = true;
  while (static_cast<int>(models.size()) < options_.max_num_models) {
    Reconstruction r(&inputs_, cameras_);
    StartModel();
    image_pair_t start = 0;
    if (!Initialize(&r, &tried, &start)) {
      if (abandoned.empty() || !may_abandon) break;
      LOG(WARNING) << "refractive_mapper: no other initial pair; building model " << models.size()
                   << " from the first one again, to the end";
      tried.erase(abandoned.front());
      may_abandon = false;
      continue;
    }
    const bool abandon_allowed =
        may_abandon && static_cast<int>(abandoned.size()) < options_.init_max_restarts;
    progress.Advance(2);
    GrowModel(&r, abandon_allowed, progress);
    if (!Abandon(abandon_allowed)) FinishModel(&r, models.size());
    if (Abandon(abandon_allowed) || (abandon_allowed && num_implausible_in_a_row_ > 0)) {
      LOG(WARNING)
          << "refractive_mapper: the intrinsics refined on " << r.poses().size()
          << " images of model " << models.size() << " came out implausible "
          << num_implausible_in_a_row_
          << " time(s) in a row: its initial pair was likely wrong; starting it again from another";
      abandoned.push_back(start);
      progress.Begin("refractive_mapper: images registered (another initial pair)",
                     inputs_.images.size());
      progress.Advance(used_.size());
      continue;
    }
    abandoned.clear();
    may_abandon = true;
    VLOG(1) << "refractive_mapper: seconds in next " << seconds_["next"] << ", register "
            << seconds_["register"] << ", triangulate " << seconds_["triangulate"] << ", local "
            << seconds_["local"] << ", global " << seconds_["global"];
    const bool keep = static_cast<int>(r.poses().size()) >= options_.min_model_size;
    for (const auto& [id, pose] : r.poses()) used_.insert(id);
    if (keep) models.push_back(MappedModel{std::move(r), start, std::move(refinements_)});
    if (!options_.multiple_models) break;
    if (inputs_.images.size() - used_.size() < 2) break;
  }
  progress.End();
  std::stable_sort(models.begin(), models.end(), [](const MappedModel& a, const MappedModel& b) {
    return a.reconstruction.poses().size() > b.reconstruction.poses().size();
  });
  return models;
}

void Mapper::StartModel() {
  port_converged_ = false;
  marker_corners_.clear();
  num_implausible_in_a_row_ = 0;
  num_settled_in_a_row_ = 0;
  refinements_.clear();
  failed_.clear();
  seconds_.clear();  // per model
}

void Mapper::GrowModel(Reconstruction* r, bool abandon_allowed, ProgressSink& progress) {
  size_t last_global = r->poses().size();
  size_t last_refine = r->poses().size();
  while (!Abandon(abandon_allowed)) {
    CancelFlag::ThrowIfRequested();
    bool added = false;
    for (image_t image_id : Timed("next", [&] { return NextImages(*r); })) {
      if (!Timed("register", [&] { return Register(r, image_id); })) {
        failed_.insert(image_id);
        continue;
      }
      failed_.clear();
      Timed("triangulate", [&] { return Triangulate(r, image_id); });
      Timed("local", [&] {
        LocalAdjust(r, image_id);
        return 0;
      });
      progress.Advance(1);
      if (r->poses().size() >= options_.ba_global_images_ratio * last_global) {
        // Intrinsics move the rays of every image (and need the exact,
        // slower error): refine them while the model is small and then
        // whenever it has grown by a third, until they have settled
        // (IncrementalMapperOptions::ba_calibration_settled_px).
        const bool refine = (r->poses().size() <= 8 || r->poses().size() >= 1.33 * last_refine) &&
                            !CalibrationSettled();
        Timed("global", [&] {
          GlobalAdjust(r, refine, AdjustmentEnd::kGrowing);
          return 0;
        });
        if (refine) last_refine = r->poses().size();
        last_global = r->poses().size();
      }
      added = true;
      break;
    }
    if (!added) break;
  }
}

void Mapper::FinishModel(Reconstruction* r, size_t model_index) {
  // Rays may have moved with the intrinsics: triangulate what is left,
  // adjust once more and filter.
  for (const auto& [id, pose] : std::map<image_t, Rigid3d>(r->poses())) Triangulate(r, id);
  const bool held = options_.ba_final_hold_weights;
  GlobalAdjust(r, true, held ? AdjustmentEnd::kWeightsSettled : AdjustmentEnd::kCostChange);
  Filter(r, nullptr);
  GlobalAdjust(r, true, held ? AdjustmentEnd::kHeldWeightsSolve : AdjustmentEnd::kCostChange);
  LOG(INFO) << "refractive_mapper: model " << model_index << ": " << r->poses().size()
            << " images, " << r->points().size() << " points, mean reprojection error "
            << r->MeanReprojectionError() << " px";
}

bool Mapper::Initialize(Reconstruction* r, std::set<image_pair_t>* tried, image_pair_t* start) {
  int trials = 0;
  for (const image_pair_t pair_id : RankInitialPairs(inputs_, cameras_, options_, used_, *tried)) {
    if (trials++ >= options_.init_max_num_trials) break;
    tried->insert(pair_id);
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    if (TryInitialPair(r, a, b)) {
      LOG(INFO) << "refractive_mapper: initial pair '" << inputs_.images.at(a).name << "' + '"
                << inputs_.images.at(b).name << "' (" << inputs_.pair_inliers.at(pair_id)
                << " inlier matches), " << r->points().size() << " points";
      *start = pair_id;
      return true;
    }
  }
  return false;
}

bool Mapper::TryInitialPair(Reconstruction* r, image_t a, image_t b) {
  if (!StartFromPair(options_, a, b, r)) return false;
  GlobalAdjust(r, false);
  Filter(r, nullptr);
  if (static_cast<int>(r->points().size()) < options_.init_min_num_inliers) {
    r->Deregister(b);
    r->Deregister(a);
    marker_corners_.clear();
    return false;
  }
  return true;
}

std::vector<image_t> Mapper::NextImages(const Reconstruction& r) const {
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

bool Mapper::Register(Reconstruction* r, image_t image_id) {
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

int Mapper::Triangulate(Reconstruction* r, image_t image_id) {
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

int Mapper::Filter(Reconstruction* r, const std::set<image_t>* images) {
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

void Mapper::LocalAdjust(Reconstruction* r, image_t image_id) {
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

void Mapper::GlobalAdjust(Reconstruction* r, bool refine_intrinsics, AdjustmentEnd end) {
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
      BogusIntrinsics(before.cameras, r->cameras(), cameras_, options_.max_focal_ratio_to_start);
  if (refine_intrinsics)
    num_implausible_in_a_row_ = implausible ? num_implausible_in_a_row_ + 1 : 0;
  if (implausible) {
    LOG(WARNING) << "refractive_mapper: intrinsics refined on " << r->poses().size()
                 << " images came out implausible (" << CalibrationText(*r, false)
                 << " ); held for now";
    before.Restore(r, &markers);
    ba = ba.WithIntrinsicsHeld();
    ba.refine_housing = false;
    AdjustBundle(r, ba, BundleAdjustmentScope(), &markers, options_.marker_scale);
  }
  if (ba.refine_housing && EndedOnItsCriterion(summary)) {
    port_converged_ = CameraWithHousingAtBound(r->cameras()) == kInvalidCameraId;
  }
  NoteRefinement(*r, ba, implausible, summary, before.cameras);
  if (VLOG_IS_ON(1) && (ba.refine_housing || ba.refine_focal_length)) {
    VLOG(1) << "global adjustment of " << r->poses().size()
            << " images:" << CalibrationText(*r, true);
  }
  Filter(r, nullptr);
}

void Mapper::AdjustHousingFirst(Reconstruction* r, const BundleAdjustmentOptions& ba,
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

void Mapper::NoteRefinement(const Reconstruction& r, const BundleAdjustmentOptions& ba,
                            bool implausible, const ceres::Solver::Summary& summary,
                            const std::map<camera_t, HousedCamera>& cameras_before) {
  const bool refined = !implausible && (ba.refine_housing || ba.refine_focal_length ||
                                        ba.refine_principal_point || ba.refine_extra_params);
  if (refined)
    refinements_.push_back(
        {static_cast<int>(r.poses().size()), std::numeric_limits<double>::infinity()});
  if (!refined || static_cast<int>(r.poses().size()) < options_.ba_calibration_settled_min_images)
    return;
  const double depth = MedianSceneDepth(r);
  double& shift = refinements_.back().image_shift_px;
  if (depth > 0 && EndedOnItsCriterion(summary)) {
    shift = 0;
    for (const auto& [id, camera] : r.cameras()) {
      shift = std::max(shift, MaxImageShiftPx(cameras_before.at(id), camera, depth));
    }
  }
  num_settled_in_a_row_ =
      shift < options_.ba_calibration_settled_px ? num_settled_in_a_row_ + 1 : 0;
  refinements_.back().settled = CalibrationSettled();
  std::ostringstream moved;
  if (!EndedOnItsCriterion(summary))
    moved << "ended before converging (image shift not measured)";
  else if (std::isinf(shift))
    moved << "had no scene depth (image shift not measured)";
  else
    moved << "moved the image by up to " << shift << " px";
  if (summary.termination_type == ceres::USER_SUCCESS)
    moved << " (ended once the robust weights settled)";
  VLOG(1) << "refractive_mapper: the refinement on " << r.poses().size() << " images "
          << moved.str() << " at the median depth " << depth
          << (CalibrationSettled() ? " (settled)" : "");
}

}  // namespace

std::vector<MappedModel> RunIncrementalMapper(const SfmInputs& inputs,
                                              const std::map<camera_t, HousedCamera>& cameras,
                                              const IncrementalMapperOptions& options,
                                              ProgressSink& progress) {
  options.Check();
  Mapper mapper(inputs, cameras, options);
  return mapper.Run(progress);
}

}  // namespace portcal
