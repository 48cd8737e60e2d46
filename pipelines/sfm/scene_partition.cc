#include "pipelines/sfm/scene_partition.h"

#include <metis.h>

#include <algorithm>
#include <set>

#include "colmap_ext/util/error.h"
#include "database/feature_types.h"

namespace portcal {

void ScenePartitionOptions::Check() const {
  if (leaf_max_num_images < 10) {
    throw OptionError("--Hierarchical.leaf_max_num_images", leaf_max_num_images, ">= 10");
  }
  if (image_overlap < 2) throw OptionError("--Hierarchical.image_overlap", image_overlap, ">= 2");
}

namespace {

// The graph in METIS' compressed form over the images 0..n-1.
struct SceneGraph {
  std::vector<image_t> images;                 // node -> image id
  std::vector<std::map<idx_t, idx_t>> weight;  // node -> neighbour -> inliers
};

SceneGraph BuildGraph(const std::map<image_pair_t, int>& pair_inliers) {
  std::set<image_t> ids;
  for (const auto& [pair_id, inliers] : pair_inliers) {
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    ids.insert(a);
    ids.insert(b);
  }
  SceneGraph graph;
  graph.images.assign(ids.begin(), ids.end());
  graph.weight.resize(graph.images.size());
  const auto node = [&](image_t id) {
    return static_cast<idx_t>(std::lower_bound(graph.images.begin(), graph.images.end(), id) -
                              graph.images.begin());
  };
  for (const auto& [pair_id, inliers] : pair_inliers) {
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    if (a == b || inliers <= 0) continue;
    graph.weight[node(a)][node(b)] += inliers;
    graph.weight[node(b)][node(a)] += inliers;
  }
  return graph;
}

// METIS' k-way cut of the graph: the part of each node.
std::vector<idx_t> CutGraph(const SceneGraph& graph, idx_t num_parts) {
  std::vector<idx_t> xadj = {0}, adjncy, adjwgt;
  for (const auto& neighbours : graph.weight) {
    for (const auto& [node, weight] : neighbours) {
      adjncy.push_back(node);
      adjwgt.push_back(weight);
    }
    xadj.push_back(static_cast<idx_t>(adjncy.size()));
  }
  idx_t num_nodes = static_cast<idx_t>(graph.images.size()), num_constraints = 1, cut = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // the same clusters every run
  std::vector<idx_t> part(graph.images.size(), 0);
  // Recursive bisection for two parts (k-way wants more), k-way beyond.
  const auto partition = num_parts == 2 ? METIS_PartGraphRecursive : METIS_PartGraphKway;
  const int status =
      partition(&num_nodes, &num_constraints, xadj.data(), adjncy.data(), nullptr, nullptr,
                adjwgt.data(), &num_parts, nullptr, nullptr, options, &cut, part.data());
  if (status != METIS_OK)
    throw NumericalError("scene partition: METIS failed (status " + std::to_string(status) + ")");
  return part;
}

// The images outside `cluster` sharing the most inliers with it, at most
// `count`.
std::vector<idx_t> StrongestNeighbours(const SceneGraph& graph, const std::vector<idx_t>& cluster,
                                       int count) {
  const std::set<idx_t> inside(cluster.begin(), cluster.end());
  std::map<idx_t, idx_t> shared;
  for (idx_t node : cluster) {
    for (const auto& [neighbour, weight] : graph.weight[static_cast<size_t>(node)]) {
      if (!inside.count(neighbour)) shared[neighbour] += weight;
    }
  }
  std::vector<std::pair<idx_t, idx_t>> ranked;  // (-inliers, node): strongest first, ties by node
  for (const auto& [node, weight] : shared) ranked.emplace_back(-weight, node);
  std::sort(ranked.begin(), ranked.end());
  std::vector<idx_t> chosen;
  for (size_t k = 0; k < ranked.size() && static_cast<int>(k) < count; ++k)
    chosen.push_back(ranked[k].second);
  return chosen;
}

}  // namespace

std::vector<std::vector<image_t>> PartitionScene(const std::map<image_pair_t, int>& pair_inliers,
                                                 const ScenePartitionOptions& options) {
  options.Check();
  const SceneGraph graph = BuildGraph(pair_inliers);
  const size_t n = graph.images.size();
  if (n == 0) return {};
  const idx_t num_parts = static_cast<idx_t>(
      (n + static_cast<size_t>(options.leaf_max_num_images) - 1) / options.leaf_max_num_images);
  if (num_parts <= 1) return {graph.images};
  const std::vector<idx_t> part = CutGraph(graph, num_parts);
  std::vector<std::vector<idx_t>> parts(static_cast<size_t>(num_parts));
  for (size_t node = 0; node < n; ++node)
    parts[static_cast<size_t>(part[node])].push_back(static_cast<idx_t>(node));
  std::vector<std::vector<image_t>> clusters;
  for (const std::vector<idx_t>& nodes : parts) {
    if (nodes.empty()) continue;
    std::vector<image_t> cluster;
    for (idx_t node : nodes) cluster.push_back(graph.images[static_cast<size_t>(node)]);
    for (idx_t node : StrongestNeighbours(graph, nodes, options.image_overlap)) {
      cluster.push_back(graph.images[static_cast<size_t>(node)]);
    }
    std::sort(cluster.begin(), cluster.end());
    clusters.push_back(cluster);
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return clusters;
}

}  // namespace portcal
