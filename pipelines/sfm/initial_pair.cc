#include "pipelines/sfm/initial_pair.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/reconstruction/ray_geometry.h"

namespace portcal {

namespace {

constexpr double kDegree = M_PI / 180.0;

// The correspondences of images a and b whose keypoints both have rays.
struct PairRays {
  std::vector<std::pair<point2D_t, point2D_t>> pairs;
  std::vector<Eigen::Vector3d> dirs_a, dirs_b;
};

PairRays RaysOfPair(const Reconstruction& r, image_t a, image_t b) {
  PairRays out;
  const SfmImage& image_a = r.inputs().images.at(a);
  for (point2D_t k = 0; k < image_a.correspondences.size(); ++k) {
    for (const Correspondence& c : image_a.correspondences[k]) {
      if (c.image_id != b) continue;
      const auto& ra = r.RayOf(a, k);
      const auto& rb = r.RayOf(b, c.point2D_idx);
      if (!ra || !rb) continue;
      out.pairs.emplace_back(k, c.point2D_idx);
      out.dirs_a.push_back(ra->direction);
      out.dirs_b.push_back(rb->direction);
    }
  }
  return out;
}

// The inlier pairs' points in a's frame (NaN where they do not triangulate
// in front of both cameras) and the triangulation angles of those that do.
void TriangulatePair(const Reconstruction& r, image_t a, image_t b, const PairRays& rays,
                     const std::vector<char>& inliers, const Rigid3d& pose_b,
                     std::vector<Eigen::Vector3d>* points, std::vector<double>* angles) {
  points->assign(rays.pairs.size(), Eigen::Vector3d::Constant(std::nan("")));
  angles->clear();
  for (size_t i = 0; i < rays.pairs.size(); ++i) {
    if (!inliers[i]) continue;
    const std::vector<Ray3d> pair = {*r.RayOf(a, rays.pairs[i].first),
                                     RayInWorld(*r.RayOf(b, rays.pairs[i].second), pose_b)};
    const auto x = TriangulateRays(pair);
    if (!x || (*x).z() <= 0 || (pose_b * *x).z() <= 0) continue;
    (*points)[i] = *x;
    angles->push_back(MaxTriangulationAngle(pair, *x));
  }
}

// Whether both images saw one marker (its dictionary and id), whose sides
// then scale their model from the start.
bool SeeACommonMarker(const SfmImage& a, const SfmImage& b) {
  for (const MarkerDetection& seen_by_a : a.markers) {
    for (const MarkerDetection& seen_by_b : b.markers) {
      if (seen_by_a.marker_id == seen_by_b.marker_id &&
          seen_by_a.dictionary == seen_by_b.dictionary)
        return true;
    }
  }
  return false;
}

}  // namespace

std::vector<image_pair_t> RankInitialPairs(const SfmInputs& inputs,
                                           const std::map<camera_t, HousedCamera>& cameras,
                                           const IncrementalMapperOptions& options,
                                           const std::set<image_t>& used,
                                           const std::set<image_pair_t>& tried) {
  // Most inlier matches first, but pairs whose geometry is a homography
  // last: a relative pose from a plane seen twice is ambiguous (two
  // decompositions), and a wrong start warps the model and sends the
  // intrinsics astray (measured: focal length 16600 px for 650 on a render
  // whose best pair saw one face of the target).
  std::vector<std::tuple<bool, int, image_pair_t>> candidates;
  for (const auto& [pair_id, count] : inputs.pair_inliers) {
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    if (used.count(a) || used.count(b) || tried.count(pair_id)) continue;
    if (count < options.init_min_num_inliers) continue;
    candidates.emplace_back(inputs.planar_pairs.count(pair_id) == 0, count, pair_id);
  }
  std::sort(candidates.rbegin(), candidates.rend());
  // Behind a housing with the markers as the scale source, pairs that see a
  // marker in common go first: refraction makes the scale more than a
  // gauge, yet barely fixes it, so a model started elsewhere grows at a
  // wrong scale until the markers come into view (docs/scale.md: 14 % small
  // at 4000 images whose markers lay under the lines registered last, the
  // rescale left to the final adjustment). At most half the trials go to
  // them: should none of them start a model, the other pairs still get
  // their turn.
  std::vector<image_pair_t> ranked;
  if (options.marker_scale.side_length_m > 0 && AnyHoused(cameras)) {
    const size_t max_first = std::max(1, options.init_max_num_trials / 2);
    for (const auto& [not_planar, count, pair_id] : candidates) {
      if (ranked.size() == max_first || !not_planar) break;
      image_t a, b;
      PairIdToImagePair(pair_id, &a, &b);
      if (SeeACommonMarker(inputs.images.at(a), inputs.images.at(b))) ranked.push_back(pair_id);
    }
  }
  const std::set<image_pair_t> first(ranked.begin(), ranked.end());
  for (const auto& candidate : candidates) {
    if (first.count(std::get<2>(candidate)) == 0) ranked.push_back(std::get<2>(candidate));
  }
  return ranked;
}

bool StartFromPair(const IncrementalMapperOptions& options, image_t a, image_t b,
                   Reconstruction* r) {
  const auto focal_of = [&](image_t id) {
    return r->cameras().at(r->inputs().images.at(id).camera_id).camera.MeanFocalLength();
  };
  const PairRays rays = RaysOfPair(*r, a, b);
  if (static_cast<int>(rays.pairs.size()) < options.init_min_num_inliers) return false;
  std::vector<char> inliers;
  const double angle = options.init_max_error_px / std::min(focal_of(a), focal_of(b));
  const auto b_from_a =
      EstimateRelativePose(rays.dirs_a, rays.dirs_b, angle, options.random_seed, &inliers);
  if (!b_from_a) return false;
  std::vector<Eigen::Vector3d> points;
  std::vector<double> angles;
  Rigid3d pose_b = *b_from_a;
  TriangulatePair(*r, a, b, rays, inliers, pose_b, &points, &angles);
  if (static_cast<int>(angles.size()) < options.init_min_num_inliers) return false;
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  if (angles[angles.size() / 2] < options.init_min_tri_angle_deg * kDegree) return false;
  // Scale: the rays' origins are in metres, so the baseline must be too
  // before the exact rays are triangulated again.
  std::vector<double> depths;
  for (const Eigen::Vector3d& x : points) {
    if (x.allFinite()) depths.push_back(x.z());
  }
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  pose_b.translation *= options.init_scene_depth_m / depths[depths.size() / 2];
  r->Register(a, Rigid3d());
  r->Register(b, pose_b);
  if (options.marker_scale.side_length_m > 0) {
    // Markers seen by both: their measured sides against the known one
    // (every corner kept: two views cannot tell a bad corner).
    if (const auto factor =
            MarkerScaleRatio(TriangulateMarkerCorners(*r, 1e9), options.marker_scale.side_length_m,
                             /*with_diagonals=*/false)) {
      pose_b.translation *= *factor;
      r->Register(b, pose_b);
    }
  }
  TriangulatePair(*r, a, b, rays, inliers, pose_b, &points, &angles);
  for (size_t i = 0; i < rays.pairs.size(); ++i) {
    if (!points[i].allFinite()) continue;
    if (r->ReprojectionError(a, rays.pairs[i].first, points[i]) > options.init_max_error_px ||
        r->ReprojectionError(b, rays.pairs[i].second, points[i]) > options.init_max_error_px) {
      continue;
    }
    r->AddPoint(points[i], {{a, rays.pairs[i].first}, {b, rays.pairs[i].second}});
  }
  if (static_cast<int>(r->points().size()) < options.init_min_num_inliers) {
    r->Deregister(b);
    r->Deregister(a);
    return false;
  }
  return true;
}

}  // namespace portcal
