// `portcal feature_masker`: keeps only the SIFT features on the calibration
// object, i.e. near its ArUco markers. Each detected marker's quad is scaled
// about its centroid by `enlargement_factor`; features inside any scaled
// quad stay in COLMAP's keypoints and descriptors tables (what COLMAP's
// matchers read), the rest are removed from them. The features as extracted
// are kept in portcal_unmasked_features, so a rerun with another factor or
// dictionary masks those again rather than what an earlier mask left.
// Detections are stored in portcal_marker_detections (they later
// pre-calibrate the intrinsics and give scale). Matches and two-view
// geometries of every image whose features change are deleted in the same
// transaction, so the database never holds matches into re-indexed
// keypoints. Rerunning is safe (the same mask again changes nothing).
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/feature/marker_detection.h"
#include "colmap_ext/util/progress.h"

namespace portcal {

struct FeatureMaskerOptions {
  std::string database_path;  // must exist, with features
  std::string image_path;     // the images the database names
  std::string dictionary = "DICT_4X4_50";
  double enlargement_factor = 3.0;  // >= 1
  // --Mask.keep_all_features: the markers are detected and stored, and
  // every feature stays as extracted (features an earlier mask removed come
  // back): a survey whose markers, seen in a part of it, give the scale.
  bool keep_all_features = false;
  int num_threads = 2;
  void Check() const;  // throws OptionError naming --Mask.* or the option
};

struct FeatureMaskerSummary {
  int num_images = 0;
  int num_without_markers = 0;
  int64_t num_markers = 0;
  int64_t num_features_before = 0;  // as extracted
  int64_t num_features_kept = 0;
};

FeatureMaskerSummary RunFeatureMasker(const FeatureMaskerOptions& options, ProgressSink& progress);

}  // namespace portcal
