// `portcal exhaustive_matcher`, `sequential_matcher` and `spatial_matcher`
// (pairs from the images' position priors, as COLMAP's): descriptor
// matching of image pairs and geometric verification, written to COLMAP's
// `matches` and `two_view_geometries` tables in one transaction. Pairs that
// already have a two-view geometry are skipped (rerunning is safe and
// resumes), unless `overwrite`.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "colmap_ext/util/progress.h"
#include "colmap_ext/util/types.h"
#include "pipelines/distributed/shards.h"
#include "pipelines/features/descriptor_matching.h"
#include "pipelines/features/two_view_verification.h"

namespace portcal {

struct SequentialPairingOptions {
  int overlap = 10;               // each image with its next `overlap` images (name order)
  bool quadratic_overlap = true;  // also with the images 2^k ahead, k < overlap
  // Loop closure by image retrieval: every `loop_detection_period`-th image
  // is matched with its `loop_detection_num_images` most similar images
  // (bag of visual words, tf-idf) outside the overlap window.
  bool loop_detection = false;
  int loop_detection_period = 10;
  int loop_detection_num_images = 20;
  int vocabulary_size = 512;  // visual words, trained on this database
  void Check() const;         // throws OptionError naming --SequentialMatching.*
};

// COLMAP's spatial matcher: each image with its nearest images by position
// prior (navigation), for surveys whose lines pass beside each other.
struct SpatialPairingOptions {
  int max_num_neighbors = 20;
  double max_distance_m = 3.0;  // between camera positions
  bool ignore_z = true;         // distances in the horizontal plane (z up or down)
  void Check() const;           // throws OptionError naming --SpatialMatching.*
};

// Which image pairs are matched: every pair, neighbours in name order (and
// loop candidates), or neighbours by position prior. One stage, three of
// COLMAP's commands (exhaustive_matcher, sequential_matcher, spatial_matcher).
enum class PairingMode { kExhaustive, kSequential, kSpatial };
// "exhaustive", "sequential", "spatial".
std::string PairingModeName(PairingMode mode);

struct FeatureMatcherOptions {
  std::string database_path;
  PairingMode mode = PairingMode::kExhaustive;
  SequentialPairingOptions sequential;
  SpatialPairingOptions spatial;
  DescriptorMatchingOptions matching;
  TwoViewVerificationOptions verification;
  bool overwrite = false;
  int num_threads = 2;
  // Only this block of the pairs to match, read from the database and
  // written into the shard database beside it (shards.h), as one rank of a
  // distributed run.
  Shard shard;
  void Check() const;  // throws OptionError naming the option
};

struct FeatureMatcherSummary {
  int64_t num_pairs = 0;     // candidate pairs
  int64_t num_matched = 0;   // matched in this run
  int64_t num_skipped = 0;   // already had a geometry
  int64_t num_verified = 0;  // with inliers, of those matched
  int64_t num_loop_pairs = 0;
};

// Candidate pairs (image_id1, image_id2) for images sorted by name.
std::vector<std::pair<image_t, image_t>> ExhaustivePairs(const std::vector<image_t>& images);
std::vector<std::pair<image_t, image_t>> SequentialPairs(const std::vector<image_t>& images,
                                                         const SequentialPairingOptions& options);

// Images without a position have no spatial pairs.
std::vector<std::pair<image_t, image_t>> SpatialPairs(const std::vector<std::pair<image_t, Eigen::Vector3d>>& positions,
                                                      const SpatialPairingOptions& options);

// In an MPI job (mpirun, srun: mpi_world.h) every rank matches its block of
// the pairs into a shard database and rank 0 copies the shards' rows into
// the database in one transaction: the same rows as one process's run.
// Every rank calls it.
FeatureMatcherSummary RunFeatureMatcher(const FeatureMatcherOptions& options, ProgressSink& progress);

}  // namespace portcal
