// `portcal hierarchical_mapper`: refractive mapping of a survey too large
// for one incremental model, as COLMAP's hierarchical_mapper does it: the
// scene graph cut into overlapping clusters (scene_partition.h), each
// cluster mapped on its own by refractive_mapper with the housing refined
// or held as the options say, the cluster models merged through their
// shared images and points (model_merger.h), then one global refractive
// adjustment of the merged model -- the housing refined with
// --Mapper.ba_refine_housing, the navigation as the scale with
// --PosePrior.position_sigma -- and an outlier filter. Under `mpirun -np N`
// (or Slurm's srun) the clusters are shared out between the ranks, each
// mapping its own; rank 0 merges and adjusts.
// Writes OUTPUT/0 (the merged model), OUTPUT/clusters/C/ (each cluster's
// models) and OUTPUT/clusters/C.txt (its images).
#pragma once

#include <vector>

#include "pipelines/sfm/model_merger.h"
#include "pipelines/sfm/scene_partition.h"
#include "pipelines/stages/refractive_mapper.h"

namespace portcal {

struct HierarchicalMapperOptions {
  // The database, the output folder, the housing and the mapper's options
  // for every cluster (its image_list_path is the stage's to set).
  RefractiveMapperOptions mapper;
  ScenePartitionOptions partition;
  ModelMergeOptions merge;
  void Check() const;  // throws OptionError naming the option
};

struct HierarchicalMapperSummary {
  int num_clusters = 0;
  int num_images = 0;      // with a verified pair
  int num_registered = 0;  // in the merged model
  std::vector<ModelAlignment> alignments;
  int num_unmapped = 0;  // clusters whose mapping failed (left out, with a warning)
  int num_left_out = 0;  // cluster models that could not be merged
  double mean_reprojection_error_px = 0;
};

HierarchicalMapperSummary RunHierarchicalMapper(const HierarchicalMapperOptions& options,
                                                ProgressSink& progress);

}  // namespace portcal
