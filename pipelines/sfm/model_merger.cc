#include "pipelines/sfm/model_merger.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "colmap_ext/util/error.h"

namespace portcal {

void ModelMergeOptions::Check() const {
  if (min_shared_points < 3) {
    throw OptionError("--Hierarchical.min_shared_points", min_shared_points, ">= 3");
  }
}

namespace {

Eigen::Vector3d Apply(const Similarity3d& s, const Eigen::Vector3d& x) {
  return s.scale * (s.rotation * x) + s.translation;
}

Similarity3d FitSelected(const std::vector<Eigen::Vector3d>& from,
                         const std::vector<Eigen::Vector3d>& to, const std::vector<char>& use) {
  const int n = static_cast<int>(std::count(use.begin(), use.end(), 1));
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (size_t i = 0, k = 0; i < from.size(); ++i) {
    if (!use[i]) continue;
    src.col(static_cast<Eigen::Index>(k)) = from[i];
    dst.col(static_cast<Eigen::Index>(k++)) = to[i];
  }
  return FitSimilarity(src, dst);
}

// A fit on all, then twice on the pairs within three robust spreads
// (1.4826 x the median distance) of the last fit: a point triangulated
// from a bad match in one model does not tilt the alignment.
void FitRobustly(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to,
                 ModelAlignment* alignment) {
  std::vector<char> use(from.size(), 1);
  Similarity3d sim = FitSelected(from, to, use);
  for (int round = 0; round < 2; ++round) {
    std::vector<double> errors(from.size());
    for (size_t i = 0; i < from.size(); ++i) errors[i] = (Apply(sim, from[i]) - to[i]).norm();
    std::vector<double> sorted = errors;
    std::nth_element(sorted.begin(),
                     sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double limit = 3.0 * 1.4826 * sorted[sorted.size() / 2];
    for (size_t i = 0; i < from.size(); ++i) use[i] = errors[i] <= limit;
    if (std::count(use.begin(), use.end(), 1) < 3) break;
    sim = FitSelected(from, to, use);
  }
  double sum_sq = 0;
  int inliers = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    if (!use[i]) continue;
    sum_sq += (Apply(sim, from[i]) - to[i]).squaredNorm();
    ++inliers;
  }
  alignment->merged_from_model = sim;
  alignment->num_inliers = inliers;
  alignment->rms = inliers ? std::sqrt(sum_sq / inliers) : 0.0;
}

// The points of `model` observed through a keypoint that also observes a
// point of `merged`: (the model's point, the merged one), one per model point.
void SharedPoints(const SparseModel& merged, const SparseModel& model,
                  std::vector<Eigen::Vector3d>* from, std::vector<Eigen::Vector3d>* to) {
  for (const auto& [id, point] : model.points3D) {
    for (const TrackElement& e : point.track) {
      const auto image = merged.images.find(e.image_id);
      if (image == merged.images.end() || e.point2D_idx >= image->second.points2D.size()) continue;
      const point3D_t shared = image->second.points2D[e.point2D_idx].point3D_id;
      if (shared == kInvalidPoint3DId) continue;
      from->push_back(point.xyz);
      to->push_back(merged.points3D.at(shared).xyz);
      break;
    }
  }
}

int NumSharedImages(const SparseModel& merged, const SparseModel& model) {
  int shared = 0;
  for (const auto& [id, image] : model.images) shared += merged.images.count(id) > 0;
  return shared;
}

// The model's images (those not merged yet) and points, moved into the
// merged frame; a point's track joins the merged point one of its keypoints
// already observes, else it becomes a point of its own.
void AddModel(const SparseModel& model, const Similarity3d& s, SparseModel* merged) {
  for (const auto& [id, image] : model.images) {
    if (merged->images.count(id)) continue;
    Image moved = image;
    // cam_from_merged = (R_c R^T, s t_c - R_c R^T t), as in AlignToPositionPriors.
    const Eigen::Quaterniond rotation =
        (image.cam_from_world.rotation * s.rotation.conjugate()).normalized();
    moved.cam_from_world =
        Rigid3d(rotation, s.scale * image.cam_from_world.translation - rotation * s.translation);
    for (Point2D& p : moved.points2D) p.point3D_id = kInvalidPoint3DId;
    merged->images[id] = moved;
  }
  point3D_t next_id = merged->points3D.empty() ? 1 : merged->points3D.rbegin()->first + 1;
  for (const auto& [id, point] : model.points3D) {
    point3D_t target = kInvalidPoint3DId;
    std::vector<TrackElement> free;
    for (const TrackElement& e : point.track) {
      const point3D_t observed =
          merged->images.at(e.image_id).points2D.at(e.point2D_idx).point3D_id;
      if (observed == kInvalidPoint3DId) free.push_back(e);
      if (observed != kInvalidPoint3DId && target == kInvalidPoint3DId) target = observed;
    }
    if (target == kInvalidPoint3DId) {
      if (free.size() < 2) continue;
      target = next_id++;
      Point3D added = point;
      added.xyz = Apply(s, point.xyz);
      added.track.clear();
      merged->points3D[target] = added;
    }
    Point3D& joined = merged->points3D.at(target);
    for (const TrackElement& e : free) {
      // One observation per image in a track: a second keypoint of an image
      // already in it is a different feature.
      const bool seen =
          std::any_of(joined.track.begin(), joined.track.end(),
                      [&](const TrackElement& t) { return t.image_id == e.image_id; });
      if (seen) continue;
      joined.track.push_back(e);
      merged->images.at(e.image_id).points2D.at(e.point2D_idx).point3D_id = target;
    }
  }
}

}  // namespace

MergedModels MergeModels(const std::vector<SparseModel>& models, const ModelMergeOptions& options) {
  options.Check();
  MergedModels result;
  if (models.empty()) return result;
  std::vector<size_t> pending(models.size());
  for (size_t i = 0; i < models.size(); ++i) pending[i] = i;
  std::stable_sort(pending.begin(), pending.end(), [&](size_t a, size_t b) {
    return models[a].images.size() > models[b].images.size();
  });
  result.model = models[pending.front()];
  ModelAlignment first;
  first.model_index = pending.front();
  first.num_shared_images = static_cast<int>(result.model.images.size());
  result.alignments.push_back(first);
  pending.erase(pending.begin());
  while (!pending.empty()) {
    // The model sharing the most images with what is merged and enough
    // points to be aligned.
    std::stable_sort(pending.begin(), pending.end(), [&](size_t a, size_t b) {
      return NumSharedImages(result.model, models[a]) > NumSharedImages(result.model, models[b]);
    });
    bool merged_one = false;
    for (auto next = pending.begin(); next != pending.end(); ++next) {
      const SparseModel& model = models[*next];
      ModelAlignment alignment;
      alignment.model_index = *next;
      alignment.num_shared_images = NumSharedImages(result.model, model);
      std::vector<Eigen::Vector3d> from, to;
      SharedPoints(result.model, model, &from, &to);
      alignment.num_shared_points = static_cast<int>(from.size());
      if (alignment.num_shared_points < options.min_shared_points) continue;
      FitRobustly(from, to, &alignment);
      AddModel(model, alignment.merged_from_model, &result.model);
      result.alignments.push_back(alignment);
      pending.erase(next);
      merged_one = true;
      break;
    }
    if (!merged_one) {
      // Nothing merged holds any of the rest.
      result.left_out = pending;
      break;
    }
  }
  return result;
}

}  // namespace portcal
