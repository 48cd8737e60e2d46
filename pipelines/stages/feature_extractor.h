// `portcal feature_extractor`: imports images into the database (as COLMAP's
// ImageReader) and stores their SIFT keypoints and descriptors in COLMAP's
// layout, so COLMAP's matchers and mapper can use them. One transaction;
// images that already have features are skipped unless `overwrite`.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
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
// as it was.
FeatureExtractorSummary RunFeatureExtractor(const FeatureExtractorOptions& options,
                                         ProgressSink& progress);

}  // namespace portcal
