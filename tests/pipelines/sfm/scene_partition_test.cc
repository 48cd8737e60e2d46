// The hierarchical mapper's two halves on their own: the scene graph cut
// into overlapping clusters, and cluster models merged back through the
// points they share.
#include "pipelines/sfm/scene_partition.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "colmap_ext/util/error.h"
#include "database/feature_types.h"
#include "pipelines/sfm/model_merger.h"

namespace portcal {
namespace {

// A lawnmower survey's graph: `lines` lines of `per_line` images, each
// paired with the next two along its line (500 and 200 inliers) and the one
// beside it on the next line (100).
std::map<image_pair_t, int> SurveyGraph(int lines, int per_line) {
  std::map<image_pair_t, int> pairs;
  const auto id = [per_line](int line, int k) {
    return static_cast<image_t>(1 + line * per_line + k);
  };
  for (int line = 0; line < lines; ++line) {
    for (int k = 0; k < per_line; ++k) {
      if (k + 1 < per_line) pairs[ImagePairToPairId(id(line, k), id(line, k + 1))] = 500;
      if (k + 2 < per_line) pairs[ImagePairToPairId(id(line, k), id(line, k + 2))] = 200;
      if (line + 1 < lines) pairs[ImagePairToPairId(id(line, k), id(line + 1, k))] = 100;
    }
  }
  return pairs;
}

TEST(ScenePartition, OverlappingClustersCoverEveryImageAndShareSome) {
  const std::map<image_pair_t, int> pairs = SurveyGraph(4, 50);  // 200 images
  ScenePartitionOptions options;
  options.leaf_max_num_images = 50;
  options.image_overlap = 10;
  const std::vector<std::vector<image_t>> clusters = PartitionScene(pairs, options);
  ASSERT_EQ(clusters.size(), 4u);
  std::map<image_t, int> membership;
  for (const auto& cluster : clusters) {
    EXPECT_TRUE(std::is_sorted(cluster.begin(), cluster.end()));
    // METIS balances within its default 3 % imbalance; each then takes its
    // overlap.
    EXPECT_LE(cluster.size(), 52u + 10u);
    EXPECT_GE(cluster.size(), 40u);
    for (image_t id : cluster) ++membership[id];
  }
  EXPECT_EQ(membership.size(), 200u);  // every image in a cluster
  int shared = 0;
  for (const auto& [id, count] : membership) shared += count > 1;
  EXPECT_GE(shared, 20);  // each cluster's overlap lies in another
  // Every cluster holds images the others hold: the models can be merged.
  for (size_t a = 0; a < clusters.size(); ++a) {
    int in_others = 0;
    for (image_t id : clusters[a]) in_others += membership[id] > 1;
    EXPECT_GE(in_others, 10) << "cluster " << a;
  }
  // The same clusters every run; one cluster when the images fit.
  EXPECT_EQ(PartitionScene(pairs, options), clusters);
  options.leaf_max_num_images = 200;
  EXPECT_EQ(PartitionScene(pairs, options).size(), 1u);
  options.leaf_max_num_images = 5;
  EXPECT_THROW(PartitionScene(pairs, options), OptionError);
}

// A model of `images` cameras in a row over a field of points, each point
// observed by every camera (keypoint k of every image is point k).
SparseModel RowModel(int images, int points, std::mt19937* rng) {
  SparseModel model;
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 1; i <= images; ++i) {
    Image image;
    image.image_id = static_cast<image_t>(i);
    image.name = std::to_string(i);
    image.camera_id = 1;
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d(0.2, 1, 0.1).normalized()));
    image.cam_from_world =
        Rigid3d(rotation, -(rotation * Eigen::Vector3d(0.5 * i, 0.1 * i * i, 0)));
    image.points2D.resize(static_cast<size_t>(points));
    model.images[image.image_id] = image;
  }
  for (int p = 0; p < points; ++p) {
    Point3D point;
    point.xyz = Eigen::Vector3d(5 * u(*rng), 2 * u(*rng), 3 + u(*rng));
    for (int i = 1; i <= images; ++i)
      point.track.push_back({static_cast<image_t>(i), static_cast<point2D_t>(p)});
    model.points3D[static_cast<point3D_t>(p + 1)] = point;
  }
  return model;
}

// The images [first, last] of `whole` and the points they observe, tracks
// cut to them, moved by `s` (a cluster's own frame).
SparseModel Cluster(const SparseModel& whole, image_t first, image_t last, const Similarity3d& s) {
  SparseModel part;
  for (image_t id = first; id <= last; ++id) {
    Image image = whole.images.at(id);
    const Eigen::Quaterniond rotation =
        (image.cam_from_world.rotation * s.rotation.conjugate()).normalized();
    image.cam_from_world =
        Rigid3d(rotation, s.scale * image.cam_from_world.translation - rotation * s.translation);
    part.images[id] = image;
  }
  for (const auto& [id, point] : whole.points3D) {
    Point3D cut = point;
    cut.xyz = s.scale * (s.rotation * point.xyz) + s.translation;
    cut.track.clear();
    for (const TrackElement& e : point.track) {
      if (e.image_id >= first && e.image_id <= last) cut.track.push_back(e);
    }
    for (const TrackElement& e : cut.track)
      part.images.at(e.image_id).points2D[e.point2D_idx].point3D_id = id;
    part.points3D[id] = cut;
  }
  return part;
}

TEST(ModelMerger, ClustersInTheirOwnFramesMergeIntoTheWholeDespiteBadPoints) {
  std::mt19937 rng(7);
  const SparseModel whole = RowModel(12, 400, &rng);
  Similarity3d identity, moved;
  moved.scale = 0.37;
  moved.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, -1).normalized()));
  moved.translation = Eigen::Vector3d(3, -7, 11);
  // Images 1-7 and 5-12 (three shared); the second cluster's frame is
  // another, and 20 of its points are triangulated 0.5 m off.
  std::vector<SparseModel> clusters = {Cluster(whole, 5, 12, moved),
                                       Cluster(whole, 1, 7, identity)};
  for (auto& [id, point] : clusters[0].points3D) {
    if (id % 20 == 0) point.xyz += Eigen::Vector3d(0.5, 0, 0);
  }
  ModelMergeOptions options;
  const MergedModels merged = MergeModels(clusters, options);
  EXPECT_TRUE(merged.left_out.empty());
  ASSERT_EQ(merged.alignments.size(), 2u);
  EXPECT_EQ(merged.alignments[0].model_index, 0u);  // the larger first (8 images)
  EXPECT_EQ(merged.alignments[1].num_shared_images, 3);
  EXPECT_EQ(merged.alignments[1].num_shared_points, 400);
  EXPECT_EQ(merged.alignments[1].num_inliers, 380);  // the bad points do not fit
  // In the first (moved) cluster's frame: the whole, moved.
  const SparseModel expected = Cluster(whole, 1, 12, moved);
  ASSERT_EQ(merged.model.images.size(), 12u);
  for (const auto& [id, image] : expected.images) {
    const Rigid3d& got = merged.model.images.at(id).cam_from_world;
    EXPECT_LT(got.rotation.angularDistance(image.cam_from_world.rotation), 1e-9) << "image " << id;
    EXPECT_LT((got.translation - image.cam_from_world.translation).norm(), 1e-9) << "image " << id;
  }
  // Each point once, its track whole again: every image's keypoint k
  // observes the same point.
  ASSERT_EQ(merged.model.points3D.size(), 400u);
  for (const auto& [id, point] : merged.model.points3D) {
    EXPECT_EQ(point.track.size(), 12u) << "point " << id;
    for (const TrackElement& e : point.track) {
      EXPECT_EQ(merged.model.images.at(e.image_id).points2D[e.point2D_idx].point3D_id, id);
    }
  }
  // A cluster sharing no image stays out, named.
  std::vector<SparseModel> apart = {Cluster(whole, 1, 5, identity),
                                    Cluster(whole, 8, 12, identity)};
  for (auto& [id, point] : apart[1].points3D) point.track.clear();
  for (auto& [id, image] : apart[1].images) {
    for (Point2D& p : image.points2D) p.point3D_id = kInvalidPoint3DId;
  }
  apart[1].points3D.clear();
  const MergedModels partial = MergeModels(apart, options);
  EXPECT_EQ(partial.left_out, std::vector<size_t>{1});
  EXPECT_EQ(partial.model.images.size(), 5u);
}

}  // namespace
}  // namespace portcal
