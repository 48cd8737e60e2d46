// `portcal feature_extractor`: imports images into the database (as COLMAP's
// ImageReader) and stores their SIFT keypoints and descriptors in COLMAP's
// layout, so COLMAP's matchers and mapper can use them. One transaction;
// images that already have features are skipped unless `overwrite`.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "pipelines/distributed/shards.h"
#include "pipelines/features/sift.h"
#include "pipelines/images/image_reader.h"

namespace portcal {

struct FeatureExtractorOptions {
  std::string database_path;  // created if missing
  std::string image_path;
  ImageReaderOptions reader;
  SiftExtractionOptions sift;
  // Re-extract images that already have features (their matches and
  // geometries are deleted in the same transaction).
  bool overwrite = false;
  int num_threads = 2;
  // Only this block of the images (by name), as one rank of a distributed
  // run writes its shard database.
  Shard shard;
  void Check() const;  // throws OptionError naming the option
};

struct FeatureExtractorSummary {
  int num_images = 0;     // images found in image_path
  int num_extracted = 0;  // extracted in this run
  int num_skipped = 0;    // already had features
  int num_unreadable = 0;
  int64_t num_features = 0;  // extracted in this run
};

// Throws InputError, DatabaseError, Cancelled; the database is then left
// as it was. In an MPI job (mpirun, srun: mpi_world.h) every rank extracts
// its block of the images into a shard database beside the database (a
// copy of it, if it exists) and rank 0 merges the shards in one
// transaction: the same rows as one process's run. Every rank calls it.
FeatureExtractorSummary RunFeatureExtractor(const FeatureExtractorOptions& options,
                                            ProgressSink& progress);

}  // namespace portcal
