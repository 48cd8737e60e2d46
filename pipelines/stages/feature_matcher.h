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
#include "pipelines/features/pairing.h"
#include "pipelines/features/two_view_verification.h"

namespace portcal {

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

// In an MPI job (mpirun, srun: mpi_world.h) every rank matches its block of
// the pairs into a shard database and rank 0 copies the shards' rows into
// the database in one transaction: the same rows as one process's run.
// Every rank calls it.
FeatureMatcherSummary RunFeatureMatcher(const FeatureMatcherOptions& options,
                                        ProgressSink& progress);

}  // namespace portcal
