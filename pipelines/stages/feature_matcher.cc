#include "pipelines/stages/feature_matcher.h"

#include <algorithm>
#include <map>
#include <sstream>
#include <unordered_set>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "database/database.h"
#include "database/database_merge.h"
#include "database/stage_run.h"
#include "pipelines/distributed/mpi_world.h"

namespace fs = std::filesystem;

namespace portcal {

void FeatureMatcherOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
  sequential.Check();
  spatial.Check();
  matching.Check();
  verification.Check();
  shard.Check();
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

// Unique unordered pairs, minus those already done unless `overwrite`.
std::vector<std::pair<image_t, image_t>> PairsToMatch(
    const std::vector<std::pair<image_t, image_t>>& candidates, bool overwrite, Database* db,
    FeatureMatcherSummary* summary) {
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
void MatchInBatches(const FeatureMatcherOptions& options,
                    const std::vector<std::pair<image_t, image_t>>& pairs,
                    const std::map<image_t, camera_t>& camera_of,
                    const std::map<camera_t, Camera>& cameras, const std::string& stage,
                    Database* db, Database* out, ProgressSink& progress,
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
      geometries[k] =
          VerifyTwoView(cameras.at(fa.camera_id), fa.keypoints, cameras.at(fb.camera_id),
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
FeatureMatcherSummary MatchPairs(const FeatureMatcherOptions& options, const std::string& stage,
                                 Database* database, Database* out, ProgressSink& progress) {
  std::vector<DatabaseImage> images = database->ReadAllImages();
  if (images.size() < 2) {
    throw InputError(options.database_path + ": " + std::to_string(images.size()) +
                     " image(s); matching needs at least 2 (run feature_extractor first)");
  }
  // Pairs without features would be written as empty rows and the stage
  // logged as done: success on nothing.
  const size_t with_features = static_cast<size_t>(std::count_if(
      images.begin(), images.end(),
      [&](const DatabaseImage& image) { return database->ExistsKeypoints(image.image_id); }));
  if (with_features < 2) {
    throw InputError(
        options.database_path + ": " + std::to_string(with_features) + " of " +
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
  const ImagePairs candidates =
      CandidatePairs({options.mode, options.sequential, options.spatial}, images, ids,
                     options.database_path, stage, database, progress, &summary.num_loop_pairs);
  const std::vector<std::pair<image_t, image_t>> pairs =
      options.shard.Block(PairsToMatch(candidates, options.overwrite, database, &summary));
  LOG(INFO) << stage << ": " << images.size() << " images, " << summary.num_pairs << " pairs, "
            << pairs.size() << " to match" << (options.shard.Whole() ? "" : " in this shard");
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

FeatureMatcherSummary RunFeatureMatcher(const FeatureMatcherOptions& options,
                                        ProgressSink& progress) {
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
