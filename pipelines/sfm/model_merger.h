// The models of overlapping clusters (scene_partition.h) merged into one,
// as COLMAP's hierarchical mapper merges its clusters: the largest model
// first, then, one at a time, the model sharing the most images with what
// is merged, aligned to it by a similarity fitted to the 3-D points both
// observe through the same keypoints (robust: a refit on the points within
// three robust spreads), its images added and its tracks joined to the
// merged points they share keypoints with. Every model names images and
// keypoints by the database's ids. The cameras and housings are the first
// model's: the global adjustment that follows refines them on everything.
#pragma once

#include <vector>

#include "colmap_ext/io/sparse_model.h"
#include "pipelines/bundle_adjustment/position_priors.h"

namespace portcal {

struct ModelMergeOptions {
  // Points observed through the same keypoints in the merged model and a
  // cluster's that a cluster needs to be aligned (--Hierarchical.min_shared_points).
  int min_shared_points = 50;
  void Check() const;  // throws OptionError naming the option
};

struct ModelAlignment {
  size_t model_index = 0;  // in the models given
  int num_shared_images = 0;
  int num_shared_points = 0;
  int num_inliers = 0;
  Similarity3d merged_from_model;
  double rms = 0;  // of the inliers after the fit, in the merged model's units
};

struct MergedModels {
  SparseModel model;
  std::vector<ModelAlignment> alignments;  // in the order merged; the first model's is the identity
  std::vector<size_t> left_out;            // models that shared too little with the rest
};

MergedModels MergeModels(const std::vector<SparseModel>& models, const ModelMergeOptions& options);

}  // namespace portcal
