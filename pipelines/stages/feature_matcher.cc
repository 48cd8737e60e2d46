#include "pipelines/stages/feature_matcher.h"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <unordered_set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "database/database.h"
#include "database/database_merge.h"
#include "database/stage_run.h"
#include "pipelines/distributed/mpi_world.h"
#include "pipelines/features/image_retrieval.h"

namespace fs = std::filesystem;

namespace portcal {

std::string PairingModeName(PairingMode mode) {
  switch (mode) {
    case PairingMode::kExhaustive: return "exhaustive";
    case PairingMode::kSequential: return "sequential";
    case PairingMode::kSpatial: return "spatial";
  }
  return "unknown";
}

void SequentialPairingOptions::Check() const {
  if (overlap < 1) throw OptionError("--SequentialMatching.overlap", std::to_string(overlap), ">= 1");
  if (loop_detection_period < 1) {
    throw OptionError("--SequentialMatching.loop_detection_period", std::to_string(loop_detection_period),
                      ">= 1");
  }
  if (loop_detection_num_images < 1) {
    throw OptionError("--SequentialMatching.loop_detection_num_images",
                      std::to_string(loop_detection_num_images), ">= 1");
  }
  if (vocabulary_size < 2) {
    throw OptionError("--SequentialMatching.vocabulary_size", std::to_string(vocabulary_size), ">= 2");
  }
}

void SpatialPairingOptions::Check() const {
  if (max_num_neighbors < 1) {
    throw OptionError("--SpatialMatching.max_num_neighbors", std::to_string(max_num_neighbors), ">= 1");
  }
  if (!(max_distance_m > 0)) {
    throw OptionError("--SpatialMatching.max_distance", std::to_string(max_distance_m), "> 0 m");
  }
}

void FeatureMatcherOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
  sequential.Check();
  spatial.Check();
  matching.Check();
  verification.Check();
  shard.Check();
}

std::vector<std::pair<image_t, image_t>> ExhaustivePairs(const std::vector<image_t>& images) {
  std::vector<std::pair<image_t, image_t>> pairs;
  for (size_t i = 0; i < images.size(); ++i) {
    for (size_t j = i + 1; j < images.size(); ++j) pairs.emplace_back(images[i], images[j]);
  }
  return pairs;
}

std::vector<std::pair<image_t, image_t>> SequentialPairs(const std::vector<image_t>& images,
                                                         const SequentialPairingOptions& options) {
  std::vector<std::pair<image_t, image_t>> pairs;
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

std::vector<std::pair<image_t, image_t>> SpatialPairs(const std::vector<std::pair<image_t, Eigen::Vector3d>>& positions,
                                                      const SpatialPairingOptions& options) {
  std::vector<std::pair<image_t, image_t>> pairs;
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
    std::partial_sort(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(k), nearest.end());
    for (size_t n = 0; n < k; ++n) pairs.emplace_back(positions[i].first, positions[nearest[n].second].first);
  }
  return pairs;
}

namespace {

struct ImageFeatures {
  camera_t camera_id = kInvalidCameraId;
  FeatureKeypoints keypoints;
  UnitDescriptors descriptors;
};

std::string OptionsText(const FeatureMatcherOptions& o) {
  std::ostringstream out;
  out << "SiftMatching.max_ratio=" << o.matching.max_ratio
      << "\nSiftMatching.max_distance=" << o.matching.max_distance
      << "\nSiftMatching.cross_check=" << o.matching.cross_check
      << "\nSiftMatching.method=" << o.matching.method
      << "\nTwoViewGeometry.max_error=" << o.verification.max_error
      << "\nTwoViewGeometry.min_num_inliers=" << o.verification.min_num_inliers;
  if (o.mode == PairingMode::kSpatial) {
    out << "\nSpatialMatching.max_num_neighbors=" << o.spatial.max_num_neighbors
        << "\nSpatialMatching.max_distance=" << o.spatial.max_distance_m
        << "\nSpatialMatching.ignore_z=" << o.spatial.ignore_z;
  }
  if (o.mode == PairingMode::kSequential) {
    out << "\nSequentialMatching.overlap=" << o.sequential.overlap
        << "\nSequentialMatching.quadratic_overlap=" << o.sequential.quadratic_overlap
        << "\nSequentialMatching.loop_detection=" << o.sequential.loop_detection;
  }
  out << "\noverwrite=" << o.overwrite << "\n";
  return out.str();
}

// Pairs between every `period`-th image and its most similar images outside
// the sequential window.
std::vector<std::pair<image_t, image_t>> LoopPairs(Database* database,
                                                   const std::vector<image_t>& images,
                                                   const SequentialPairingOptions& options,
                                                   ProgressSink& progress) {
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
  std::vector<std::pair<image_t, image_t>> pairs;
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

// The candidate pairs of the mode (and, sequential, the loop candidates).
std::vector<std::pair<image_t, image_t>> CandidatePairs(const FeatureMatcherOptions& options,
                                                        const std::vector<DatabaseImage>& images,
                                                        const std::vector<image_t>& ids, const std::string& stage,
                                                        Database* db, ProgressSink& progress,
                                                        FeatureMatcherSummary* summary) {
  std::vector<std::pair<image_t, image_t>> candidates;
  if (options.mode == PairingMode::kExhaustive) {
    candidates = ExhaustivePairs(ids);
  } else if (options.mode == PairingMode::kSequential) {
    candidates = SequentialPairs(ids, options.sequential);
  } else {
    std::vector<std::pair<image_t, Eigen::Vector3d>> positions;
    for (const DatabaseImage& image : images) {
      if (const auto position = image.PriorPosition()) positions.emplace_back(image.image_id, *position);
    }
    if (positions.size() < 2) {
      throw InputError(options.database_path + ": " + std::to_string(positions.size()) +
                       " image(s) with a position prior; spatial matching needs them (run pose_prior_importer)");
    }
    if (positions.size() < images.size()) {
      LOG(WARNING) << stage << ": " << images.size() - positions.size()
                   << " image(s) without a position prior are not matched";
    }
    candidates = SpatialPairs(positions, options.spatial);
  }
  if (options.mode == PairingMode::kSequential && options.sequential.loop_detection) {
    const auto loops = LoopPairs(db, ids, options.sequential, progress);
    summary->num_loop_pairs = static_cast<int64_t>(loops.size());
    candidates.insert(candidates.end(), loops.begin(), loops.end());
  }
  return candidates;
}

// Unique unordered pairs, minus those already done unless `overwrite`.
std::vector<std::pair<image_t, image_t>> PairsToMatch(const std::vector<std::pair<image_t, image_t>>& candidates,
                                                      bool overwrite, Database* db, FeatureMatcherSummary* summary) {
  std::unordered_set<image_pair_t> done;
  if (!overwrite) {
    for (image_pair_t id : db->ReadTwoViewGeometryPairIds()) done.insert(id);
  }
  std::vector<std::pair<image_t, image_t>> pairs;
  std::unordered_set<image_pair_t> seen;
  for (const auto& [a, b] : candidates) {
    const image_pair_t id = ImagePairToPairId(a, b);
    if (!seen.insert(id).second) continue;
    if (done.count(id)) {
      ++summary->num_skipped;
      continue;
    }
    pairs.emplace_back(a, b);
  }
  summary->num_pairs = static_cast<int64_t>(seen.size());
  return pairs;
}

// Matches and verifies `pairs` in batches and writes them to `out`; the features a
// batch needs are loaded once, by this thread (the database connection is
// not shared), and dropped when no later batch needs them, so memory stays
// bounded on long surveys.
void MatchInBatches(const FeatureMatcherOptions& options, const std::vector<std::pair<image_t, image_t>>& pairs,
                    const std::map<image_t, camera_t>& camera_of, const std::map<camera_t, Camera>& cameras,
                    const std::string& stage, Database* db, Database* out, ProgressSink& progress,
                    FeatureMatcherSummary* summary) {
  constexpr size_t kBatchSize = 256;
  std::map<image_t, size_t> last_use;
  for (size_t p = 0; p < pairs.size(); ++p) {
    last_use[pairs[p].first] = p / kBatchSize;
    last_use[pairs[p].second] = p / kBatchSize;
  }
  std::map<image_t, ImageFeatures> cache;
  progress.Begin(stage + ": pairs", pairs.size());
  for (size_t start = 0; start < pairs.size(); start += kBatchSize) {
    const size_t batch = start / kBatchSize;
    const size_t end = std::min(pairs.size(), start + kBatchSize);
    for (size_t p = start; p < end; ++p) {
      for (image_t id : {pairs[p].first, pairs[p].second}) {
        if (cache.count(id)) continue;
        ImageFeatures& f = cache[id];
        f.camera_id = camera_of.at(id);
        f.keypoints = db->ReadKeypoints(id);
        f.descriptors = ToUnitDescriptors(db->ReadDescriptors(id));
        if (static_cast<size_t>(f.descriptors.rows()) != f.keypoints.size()) {
          throw InputError(options.database_path + ": " + db->ImageLabel(id) + " has " +
                           std::to_string(f.keypoints.size()) + " keypoints but " +
                           std::to_string(f.descriptors.rows()) + " descriptors");
        }
      }
    }
    std::vector<FeatureMatches> matches(end - start);
    std::vector<TwoViewGeometry> geometries(end - start);
    ParallelFor(end - start, options.num_threads, [&](size_t k) {
      const auto& [a, b] = pairs[start + k];
      const ImageFeatures& fa = cache.at(a);
      const ImageFeatures& fb = cache.at(b);
      matches[k] = MatchDescriptors(fa.descriptors, fb.descriptors, options.matching);
      geometries[k] = VerifyTwoView(cameras.at(fa.camera_id), fa.keypoints, cameras.at(fb.camera_id),
                                    fb.keypoints, matches[k], options.verification);
      progress.Advance(1);
    });
    for (size_t k = 0; k < matches.size(); ++k) {
      const auto& [a, b] = pairs[start + k];
      out->WriteMatches(a, b, matches[k]);
      out->WriteTwoViewGeometry(a, b, geometries[k]);
      ++summary->num_matched;
      summary->num_verified += !geometries[k].inlier_matches.empty();
    }
    for (auto it = cache.begin(); it != cache.end();) {
      it = last_use.at(it->first) <= batch ? cache.erase(it) : std::next(it);
    }
  }
  progress.End();
}

// Matches this shard's block of the pairs (all of them for a whole run)
// from `database` into `out`.
FeatureMatcherSummary MatchPairs(const FeatureMatcherOptions& options, const std::string& stage, Database* database,
                                 Database* out, ProgressSink& progress) {
  std::vector<DatabaseImage> images = database->ReadAllImages();
  if (images.size() < 2) {
    throw InputError(options.database_path + ": " + std::to_string(images.size()) +
                     " image(s); matching needs at least 2 (run feature_extractor first)");
  }
  // Pairs without features would be written as empty rows and the stage
  // logged as done: success on nothing.
  const size_t with_features =
      static_cast<size_t>(std::count_if(images.begin(), images.end(), [&](const DatabaseImage& image) {
        return database->ExistsKeypoints(image.image_id);
      }));
  if (with_features < 2) {
    throw InputError(options.database_path + ": " + std::to_string(with_features) + " of " +
                     std::to_string(images.size()) +
                     " images have features; matching needs at least 2 (run feature_extractor first)");
  }
  std::sort(images.begin(), images.end(),
            [](const DatabaseImage& a, const DatabaseImage& b) { return a.name < b.name; });
  std::vector<image_t> ids;
  std::map<image_t, camera_t> camera_of;
  for (const DatabaseImage& image : images) {
    ids.push_back(image.image_id);
    camera_of[image.image_id] = image.camera_id;
  }
  std::map<camera_t, Camera> cameras;
  for (const Camera& camera : database->ReadAllCameras()) cameras[camera.camera_id] = camera;

  FeatureMatcherSummary summary;
  const std::vector<std::pair<image_t, image_t>> candidates =
      CandidatePairs(options, images, ids, stage, database, progress, &summary);
  const std::vector<std::pair<image_t, image_t>> pairs =
      options.shard.Block(PairsToMatch(candidates, options.overwrite, database, &summary));
  LOG(INFO) << stage << ": " << images.size() << " images, " << summary.num_pairs << " pairs, " << pairs.size()
            << " to match" << (options.shard.Whole() ? "" : " in this shard");
  MatchInBatches(options, pairs, camera_of, cameras, stage, database, out, progress, &summary);
  return summary;
}

std::map<std::string, int64_t> Counts(const FeatureMatcherSummary& summary) {
  return {{"pairs", summary.num_pairs},
          {"matched", summary.num_matched},
          {"skipped", summary.num_skipped},
          {"verified", summary.num_verified},
          {"loop_pairs", summary.num_loop_pairs}};
}

// One rank's block into its shard database (a new file, the database's
// layout).
FeatureMatcherSummary MatchShard(const FeatureMatcherOptions& options, const std::string& stage,
                                 ProgressSink& progress) {
  StageRun run(stage, OptionsText(options));
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  const fs::path shard_path = ShardDatabasePath(options.database_path, options.shard);
  Database shard(shard_path, Database::OpenMode::kCreate, NewestVersionWith(database.layout()));
  Transaction transaction = shard.BeginTransaction();
  const FeatureMatcherSummary summary = MatchPairs(options, stage, &database, &shard, progress);
  run.Finish(&shard, Counts(summary));
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  return summary;
}

// RunFeatureMatcher on every rank of the MPI job (see the header).
FeatureMatcherSummary RunOnRanks(const FeatureMatcherOptions& options, const std::string& stage,
                                 ProgressSink& progress) {
  StageRun run(stage, OptionsText(options));
  const Shard shard = ThisRanksShard();
  const fs::path shard_path = ShardDatabasePath(options.database_path, shard);
  const auto remove_shard = [&] { RemoveShardDatabase(shard_path); };
  FeatureMatcherSummary summary;
  RunOnEveryRank(
      stage,
      [&] {
        remove_shard();
        FeatureMatcherOptions part = options;
        part.shard = shard;
        summary = MatchShard(part, stage, progress);
      },
      remove_shard);
  // Every rank counted the same candidates and skipped pairs; the matched
  // and verified ones are split.
  summary.num_matched = MpiWorld::Sum(summary.num_matched);
  summary.num_verified = MpiWorld::Sum(summary.num_verified);
  RunOnEveryRank(
      stage,
      [&] {
        if (shard.index != 0) return;
        Database database(options.database_path, Database::OpenMode::kReadWrite);
        Transaction transaction = database.BeginTransaction();
        for (int index = 0; index < shard.count; ++index) {
          Database part(ShardDatabasePath(options.database_path, Shard{index, shard.count}),
                        Database::OpenMode::kReadOnly);
          CopyPairRows(&part, &database);
        }
        run.Finish(&database, Counts(summary));
        CancelFlag::ThrowIfRequested();
        transaction.Commit();
      },
      remove_shard);
  remove_shard();
  return summary;
}

}  // namespace

FeatureMatcherSummary RunFeatureMatcher(const FeatureMatcherOptions& options, ProgressSink& progress) {
  options.Check();
  const std::string stage = PairingModeName(options.mode) + "_matcher";
  if (options.shard.Whole() && MpiWorld::Distributed()) return RunOnRanks(options, stage, progress);
  if (!options.shard.Whole()) return MatchShard(options, stage, progress);
  StageRun run(stage, OptionsText(options));
  Database database(options.database_path, Database::OpenMode::kReadWrite);
  Transaction transaction = database.BeginTransaction();
  const FeatureMatcherSummary summary = MatchPairs(options, stage, &database, &database, progress);
  run.Finish(&database, Counts(summary));
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  LOG(INFO) << stage << ": " << summary.num_matched << " pairs matched, " << summary.num_verified
            << " verified, " << summary.num_skipped << " skipped (done before)";
  return summary;
}

}  // namespace portcal
