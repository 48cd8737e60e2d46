// Which image pairs a matcher matches: COLMAP's exhaustive, sequential (name
// order, with loop candidates by image retrieval) and spatial (position
// priors) pairing, as COLMAP keeps them in controllers/pairing.cc apart
// from the matching itself.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "colmap_ext/util/progress.h"
#include "colmap_ext/util/types.h"
#include "database/database.h"

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

using ImagePairs = std::vector<std::pair<image_t, image_t>>;

// Candidate pairs (image_id1, image_id2) for images sorted by name.
ImagePairs ExhaustivePairs(const std::vector<image_t>& images);
ImagePairs SequentialPairs(const std::vector<image_t>& images,
                           const SequentialPairingOptions& options);

// Images without a position have no spatial pairs.
ImagePairs SpatialPairs(const std::vector<std::pair<image_t, Eigen::Vector3d>>& positions,
                        const SpatialPairingOptions& options);

// Pairs between every `loop_detection_period`-th image and its most similar
// images outside the sequential window (a vocabulary trained on this
// database's descriptors).
ImagePairs LoopPairs(Database* database, const std::vector<image_t>& images,
                     const SequentialPairingOptions& options, ProgressSink& progress);

// The candidate pairs of `mode` over `images` (`ids` their ids in name
// order), and, sequential with loop detection, the loop candidates (their
// number in `num_loop_pairs`). Throws InputError naming `database_path`
// when spatial pairing finds fewer than two position priors.
struct PairingChoice {
  PairingMode mode = PairingMode::kExhaustive;
  const SequentialPairingOptions& sequential;
  const SpatialPairingOptions& spatial;
};
ImagePairs CandidatePairs(const PairingChoice& choice, const std::vector<DatabaseImage>& images,
                          const std::vector<image_t>& ids, const std::string& database_path,
                          const std::string& stage, Database* database, ProgressSink& progress,
                          int64_t* num_loop_pairs);

}  // namespace portcal
