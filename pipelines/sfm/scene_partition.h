// The scene graph of a survey cut into overlapping clusters that can be
// mapped apart (as COLMAP's hierarchical mapper does): images are nodes,
// verified pairs edges weighted by their inlier matches; METIS cuts the
// graph into parts of about leaf_max_num_images with the least inlier
// weight across the cuts, then each part takes the images outside it that
// share the most inliers with it, so that neighbouring clusters' models
// share images (and through them points) to be merged by.
#pragma once

#include <map>
#include <vector>

#include "colmap_ext/util/types.h"

namespace portcal {

struct ScenePartitionOptions {
  int leaf_max_num_images =
      250;  // --Hierarchical.leaf_max_num_images: a cluster's size before the overlap
  int image_overlap = 50;  // --Hierarchical.image_overlap: images each cluster takes from outside
  void Check() const;      // throws OptionError naming the option
};

// The clusters, each a sorted list of image ids, largest first. Every image
// of a verified pair is in at least one. One cluster when the images fit.
std::vector<std::vector<image_t>> PartitionScene(const std::map<image_pair_t, int>& pair_inliers,
                                                 const ScenePartitionOptions& options);

}  // namespace portcal
