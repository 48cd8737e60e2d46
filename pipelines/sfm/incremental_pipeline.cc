#include "pipelines/sfm/incremental_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "colmap_ext/util/logging.h"
#include "pipelines/sfm/camera_change.h"
#include "pipelines/sfm/global_adjustment.h"
#include "pipelines/sfm/incremental_mapper.h"
#include "pipelines/sfm/initial_pair.h"

namespace portcal {
namespace {

class Pipeline {
 public:
  Pipeline(const SfmInputs& inputs, const std::map<camera_t, HousedCamera>& cameras,
           const IncrementalMapperOptions& options)
      : inputs_(inputs), cameras_(cameras), options_(options), mapper_(inputs, cameras, options) {}

  std::vector<MappedModel> Run(ProgressSink& progress);

 private:
  // The pair it started from in `start`.
  bool Initialize(Reconstruction* r, std::set<image_pair_t>* tried, image_pair_t* start);
  bool TryInitialPair(Reconstruction* r, image_t a, image_t b);
  // The mapper's global adjustment, its outcome recorded, then filtering.
  void GlobalAdjust(Reconstruction* r, bool refine_intrinsics,
                    AdjustmentEnd end = AdjustmentEnd::kCostChange);
  // Records a global adjustment's refinement of the calibration and whether
  // it has settled.
  void NoteRefinement(const Reconstruction& r, const BundleAdjustmentOptions& ba, bool implausible,
                      const ceres::Solver::Summary& summary,
                      const std::map<camera_t, HousedCamera>& cameras_before);
  // Clears what is tracked about the model grown.
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

  const SfmInputs& inputs_;
  const std::map<camera_t, HousedCamera>& cameras_;
  const IncrementalMapperOptions& options_;
  IncrementalMapper mapper_;
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

std::vector<MappedModel> Pipeline::Run(ProgressSink& progress) {
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
      progress.Advance(mapper_.used().size());
      continue;
    }
    abandoned.clear();
    may_abandon = true;
    VLOG(1) << "refractive_mapper: seconds in next " << seconds_["next"] << ", register "
            << seconds_["register"] << ", triangulate " << seconds_["triangulate"] << ", local "
            << seconds_["local"] << ", global " << seconds_["global"];
    const bool keep = static_cast<int>(r.poses().size()) >= options_.min_model_size;
    mapper_.EndModel(r);
    if (keep) models.push_back(MappedModel{std::move(r), start, std::move(refinements_)});
    if (!options_.multiple_models) break;
    if (inputs_.images.size() - mapper_.used().size() < 2) break;
  }
  progress.End();
  std::stable_sort(models.begin(), models.end(), [](const MappedModel& a, const MappedModel& b) {
    return a.reconstruction.poses().size() > b.reconstruction.poses().size();
  });
  return models;
}

void Pipeline::StartModel() {
  mapper_.BeginModel();
  num_implausible_in_a_row_ = 0;
  num_settled_in_a_row_ = 0;
  refinements_.clear();
  seconds_.clear();  // per model
}

void Pipeline::GrowModel(Reconstruction* r, bool abandon_allowed, ProgressSink& progress) {
  size_t last_global = r->poses().size();
  size_t last_refine = r->poses().size();
  while (!Abandon(abandon_allowed)) {
    CancelFlag::ThrowIfRequested();
    bool added = false;
    for (image_t image_id : Timed("next", [&] { return mapper_.NextImages(*r); })) {
      if (!Timed("register", [&] { return mapper_.RegisterImage(r, image_id); })) continue;
      Timed("triangulate", [&] { return mapper_.Triangulate(r, image_id); });
      Timed("local", [&] {
        mapper_.LocalAdjust(r, image_id);
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

void Pipeline::FinishModel(Reconstruction* r, size_t model_index) {
  // Rays may have moved with the intrinsics: triangulate what is left,
  // adjust once more and filter.
  for (const auto& [id, pose] : std::map<image_t, Rigid3d>(r->poses())) mapper_.Triangulate(r, id);
  const bool held = options_.ba_final_hold_weights;
  GlobalAdjust(r, true, held ? AdjustmentEnd::kWeightsSettled : AdjustmentEnd::kCostChange);
  mapper_.Filter(r, nullptr);
  GlobalAdjust(r, true, held ? AdjustmentEnd::kHeldWeightsSolve : AdjustmentEnd::kCostChange);
  LOG(INFO) << "refractive_mapper: model " << model_index << ": " << r->poses().size()
            << " images, " << r->points().size() << " points, mean reprojection error "
            << r->MeanReprojectionError() << " px";
}

bool Pipeline::Initialize(Reconstruction* r, std::set<image_pair_t>* tried, image_pair_t* start) {
  int trials = 0;
  for (const image_pair_t pair_id :
       RankInitialPairs(inputs_, cameras_, options_, mapper_.used(), *tried)) {
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

bool Pipeline::TryInitialPair(Reconstruction* r, image_t a, image_t b) {
  if (!StartFromPair(options_, a, b, r)) return false;
  GlobalAdjust(r, false);
  mapper_.Filter(r, nullptr);
  if (static_cast<int>(r->points().size()) < options_.init_min_num_inliers) {
    r->Deregister(b);
    r->Deregister(a);
    mapper_.ForgetMarkerCorners();
    return false;
  }
  return true;
}

void Pipeline::NoteRefinement(const Reconstruction& r, const BundleAdjustmentOptions& ba,
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

void Pipeline::GlobalAdjust(Reconstruction* r, bool refine_intrinsics, AdjustmentEnd end) {
  const GlobalAdjustmentOutcome outcome = mapper_.AdjustGlobally(r, refine_intrinsics, end);
  if (outcome.refined_intrinsics) {
    num_implausible_in_a_row_ = outcome.implausible ? num_implausible_in_a_row_ + 1 : 0;
  }
  NoteRefinement(*r, outcome.ba, outcome.implausible, outcome.summary, outcome.cameras_before);
  if (VLOG_IS_ON(1) && (outcome.ba.refine_housing || outcome.ba.refine_focal_length)) {
    VLOG(1) << "global adjustment of " << r->poses().size()
            << " images:" << CalibrationText(*r, true);
  }
  mapper_.Filter(r, nullptr);
}

}  // namespace

std::vector<MappedModel> RunIncrementalMapper(const SfmInputs& inputs,
                                              const std::map<camera_t, HousedCamera>& cameras,
                                              const IncrementalMapperOptions& options,
                                              ProgressSink& progress) {
  options.Check();
  Pipeline pipeline(inputs, cameras, options);
  return pipeline.Run(progress);
}

}  // namespace portcal
