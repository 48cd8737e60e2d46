#include "pipelines/features/pairing.h"

#include <algorithm>
#include <cstdlib>
#include <set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "pipelines/features/descriptor_matching.h"
#include "pipelines/features/image_retrieval.h"

namespace portcal {

std::string PairingModeName(PairingMode mode) {
  switch (mode) {
    case PairingMode::kExhaustive:
      return "exhaustive";
    case PairingMode::kSequential:
      return "sequential";
    case PairingMode::kSpatial:
      return "spatial";
  }
  return "unknown";
}

void SequentialPairingOptions::Check() const {
  if (overlap < 1) throw OptionError("--SequentialMatching.overlap", overlap, ">= 1");
  if (loop_detection_period < 1) {
    throw OptionError("--SequentialMatching.loop_detection_period", loop_detection_period, ">= 1");
  }
  if (loop_detection_num_images < 1) {
    throw OptionError("--SequentialMatching.loop_detection_num_images", loop_detection_num_images,
                      ">= 1");
  }
  if (vocabulary_size < 2) {
    throw OptionError("--SequentialMatching.vocabulary_size", vocabulary_size, ">= 2");
  }
}

void SpatialPairingOptions::Check() const {
  if (max_num_neighbors < 1) {
    throw OptionError("--SpatialMatching.max_num_neighbors", max_num_neighbors, ">= 1");
  }
  if (!(max_distance_m > 0)) {
    throw OptionError("--SpatialMatching.max_distance", max_distance_m, "> 0 m");
  }
}

ImagePairs ExhaustivePairs(const std::vector<image_t>& images) {
  std::vector<std::pair<image_t, image_t>> pairs;
  for (size_t i = 0; i < images.size(); ++i) {
    for (size_t j = i + 1; j < images.size(); ++j) pairs.emplace_back(images[i], images[j]);
  }
  return pairs;
}

ImagePairs SequentialPairs(const std::vector<image_t>& images,
                           const SequentialPairingOptions& options) {
  ImagePairs pairs;
  const size_t n = images.size();
  for (size_t i = 0; i < n; ++i) {
    std::set<size_t> ahead;
    for (int k = 1; k <= options.overlap; ++k) ahead.insert(i + static_cast<size_t>(k));
    if (options.quadratic_overlap) {
      for (int k = 0; k < options.overlap && k < 40; ++k) ahead.insert(i + (size_t{1} << k));
    }
    for (size_t j : ahead) {
      if (j < n) pairs.emplace_back(images[i], images[j]);
    }
  }
  return pairs;
}

ImagePairs SpatialPairs(const std::vector<std::pair<image_t, Eigen::Vector3d>>& positions,
                        const SpatialPairingOptions& options) {
  ImagePairs pairs;
  std::vector<std::pair<double, size_t>> nearest;
  for (size_t i = 0; i < positions.size(); ++i) {
    nearest.clear();
    for (size_t j = 0; j < positions.size(); ++j) {
      if (j == i) continue;
      Eigen::Vector3d d = positions[j].second - positions[i].second;
      if (options.ignore_z) d.z() = 0;
      const double distance = d.norm();
      if (distance <= options.max_distance_m) nearest.emplace_back(distance, j);
    }
    const size_t k = std::min(nearest.size(), static_cast<size_t>(options.max_num_neighbors));
    std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(k),
                      nearest.end());
    for (size_t n = 0; n < k; ++n)
      pairs.emplace_back(positions[i].first, positions[nearest[n].second].first);
  }
  return pairs;
}

ImagePairs LoopPairs(Database* database, const std::vector<image_t>& images,
                     const SequentialPairingOptions& options, ProgressSink& progress) {
  // Vocabulary from the descriptors of up to 200 images spread over the
  // sequence; then each image's words, one image in memory at a time.
  const size_t stride = std::max<size_t>(1, images.size() / 200);
  std::vector<UnitDescriptors> samples;
  for (size_t i = 0; i < images.size(); i += stride) {
    samples.push_back(ToUnitDescriptors(database->ReadDescriptors(images[i])));
  }
  const VisualVocabulary vocabulary = VisualVocabulary::Train(samples, options.vocabulary_size);
  samples.clear();
  ImageRetrievalIndex index(vocabulary.NumWords());
  progress.Begin("sequential_matcher: retrieval index", images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    CancelFlag::ThrowIfRequested();
    index.Add(vocabulary.Assign(ToUnitDescriptors(database->ReadDescriptors(images[i]))));
    progress.Advance(1);
  }
  progress.End();
  index.Finalize();
  ImagePairs pairs;
  const int window = options.overlap;
  for (size_t i = 0; i < images.size(); i += static_cast<size_t>(options.loop_detection_period)) {
    const int q = static_cast<int>(i);
    for (int j : index.Query(q, options.loop_detection_num_images,
                             [&](int other) { return std::abs(other - q) <= window; })) {
      pairs.emplace_back(images[i], images[static_cast<size_t>(j)]);
    }
  }
  return pairs;
}

ImagePairs CandidatePairs(const PairingChoice& choice, const std::vector<DatabaseImage>& images,
                          const std::vector<image_t>& ids, const std::string& database_path,
                          const std::string& stage, Database* database, ProgressSink& progress,
                          int64_t* num_loop_pairs) {
  ImagePairs candidates;
  if (choice.mode == PairingMode::kExhaustive) {
    candidates = ExhaustivePairs(ids);
  } else if (choice.mode == PairingMode::kSequential) {
    candidates = SequentialPairs(ids, choice.sequential);
  } else {
    std::vector<std::pair<image_t, Eigen::Vector3d>> positions;
    for (const DatabaseImage& image : images) {
      if (const auto position = image.PriorPosition())
        positions.emplace_back(image.image_id, *position);
    }
    if (positions.size() < 2) {
      throw InputError(
          database_path + ": " + std::to_string(positions.size()) +
          " image(s) with a position prior; spatial matching needs them (run pose_prior_importer)");
    }
    if (positions.size() < images.size()) {
      LOG(WARNING) << stage << ": " << images.size() - positions.size()
                   << " image(s) without a position prior are not matched";
    }
    candidates = SpatialPairs(positions, choice.spatial);
  }
  *num_loop_pairs = 0;
  if (choice.mode == PairingMode::kSequential && choice.sequential.loop_detection) {
    const ImagePairs loops = LoopPairs(database, ids, choice.sequential, progress);
    *num_loop_pairs = static_cast<int64_t>(loops.size());
    candidates.insert(candidates.end(), loops.begin(), loops.end());
  }
  return candidates;
}

}  // namespace portcal
