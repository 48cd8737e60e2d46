#include "pipelines/stages/feature_extractor.h"

#include <algorithm>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/parallel.h"
#include "colmap_ext/util/string_utils.h"
#include "database/database.h"
#include "database/database_merge.h"
#include "database/new_database_file.h"
#include "database/stage_run.h"
#include "pipelines/distributed/mpi_world.h"

namespace fs = std::filesystem;

namespace portcal {

void FeatureExtractorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (image_path.empty()) throw OptionError("--image_path", "''", "a directory of images");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
  reader.Check();
  sift.Check();
  shard.Check();
}

namespace {

std::string OptionsText(const FeatureExtractorOptions& o) {
  std::ostringstream out;
  out << "image_path=" << o.image_path << "\nImageReader.camera_model=" << o.reader.camera_model
      << "\nImageReader.single_camera=" << o.reader.single_camera
      << "\nImageReader.single_camera_per_folder=" << o.reader.single_camera_per_folder
      << "\nImageReader.camera_params=" << o.reader.camera_params
      << "\nSiftExtraction.max_num_features=" << o.sift.max_num_features
      << "\nSiftExtraction.max_image_size=" << o.sift.max_image_size
      << "\nSiftExtraction.first_octave=" << o.sift.first_octave
      << "\nSiftExtraction.peak_threshold=" << o.sift.peak_threshold
      << "\nSiftExtraction.edge_threshold=" << o.sift.edge_threshold
      << "\noverwrite=" << o.overwrite << "\n";
  return out.str();
}

struct Extracted {
  bool readable = false;
  std::string skip_reason;  // why an image is not used: unreadable, too small
  int width = 0, height = 0;
  SiftFeatures features;
};

std::map<std::string, int64_t> Counts(const FeatureExtractorSummary& summary) {
  return {{"images", summary.num_images},
          {"extracted", summary.num_extracted},
          {"skipped", summary.num_skipped},
          {"unreadable", summary.num_unreadable},
          {"features", summary.num_features}};
}

// Success on nothing would log the stage as done with no image.
void CheckSomethingExtracted(const FeatureExtractorOptions& options,
                             const FeatureExtractorSummary& summary) {
  if (summary.num_extracted > 0 && summary.num_features == 0) {
    // A database of images without a feature is no work done: the matcher
    // would find nothing, far from the cause.
    throw InputError(options.image_path + ": no SIFT feature in any of the " +
                     std::to_string(summary.num_extracted) +
                     " images (blank or featureless images, or --SiftExtraction.peak_threshold " +
                     FormatShortest(options.sift.peak_threshold) + " / edge_threshold too strict)");
  }
  if (summary.num_extracted > 0 || summary.num_skipped > 0) return;
  throw InputError(options.image_path + ": none of the " + std::to_string(summary.num_images) +
                   " image files could be read and used (unreadable, or under " +
                   std::to_string(kMinImageSide) + " px a side)");
}

FeatureExtractorSummary SumOverRanks(const FeatureExtractorSummary& mine) {
  FeatureExtractorSummary sum;
  sum.num_images = static_cast<int>(MpiWorld::Sum(mine.num_images));
  sum.num_extracted = static_cast<int>(MpiWorld::Sum(mine.num_extracted));
  sum.num_skipped = static_cast<int>(MpiWorld::Sum(mine.num_skipped));
  sum.num_unreadable = static_cast<int>(MpiWorld::Sum(mine.num_unreadable));
  sum.num_features = MpiWorld::Sum(mine.num_features);
  return sum;
}

MergeOptions::CameraSharing SharingOf(const ImageReaderOptions& reader) {
  if (reader.single_camera) return MergeOptions::CameraSharing::kAll;
  if (reader.single_camera_per_folder) return MergeOptions::CameraSharing::kPerFolder;
  return MergeOptions::CameraSharing::kNone;
}

// Rank 0: the shards into the database, in rank order, in one transaction.
void MergeShards(const FeatureExtractorOptions& options, const MergeOptions& merge,
                 const FeatureExtractorSummary& total, StageRun* run) {
  CheckSomethingExtracted(options, total);
  NewDatabaseFile new_file(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  Transaction transaction = database.BeginTransaction();
  for (int index = 0; index < MpiWorld::Size(); ++index) {
    Database shard(ShardDatabasePath(options.database_path, Shard{index, MpiWorld::Size()}),
                   Database::OpenMode::kReadOnly);
    MergeDatabase(&shard, &database, merge);
  }
  run->Finish(&database, Counts(total));
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  new_file.Keep();
}

// RunFeatureExtractor on every rank of the MPI job (see the header).
FeatureExtractorSummary RunOnRanks(const FeatureExtractorOptions& options, ProgressSink& progress) {
  if (options.overwrite || options.reader.overwrite) {
    throw OptionError(options.overwrite ? "--overwrite" : "--ImageReader.overwrite", "1",
                      "0 under mpirun (re-extract or re-import in one process)");
  }
  StageRun run("feature_extractor", OptionsText(options));
  const Shard shard = ThisRanksShard();
  const fs::path shard_path = ShardDatabasePath(options.database_path, shard);
  const auto remove_shard = [&] { RemoveShardDatabase(shard_path); };
  MergeOptions merge;
  merge.camera_sharing = SharingOf(options.reader);
  FeatureExtractorSummary mine;
  RunOnEveryRank(
      "feature_extractor",
      [&] {
        remove_shard();
        if (fs::exists(options.database_path)) {
          Database base(options.database_path, Database::OpenMode::kReadOnly);
          for (const Camera& camera : base.ReadAllCameras()) {
            merge.base_camera_id = std::max(merge.base_camera_id, camera.camera_id);
          }
          for (const DatabaseImage& image : base.ReadAllImages()) {
            merge.base_image_id = std::max(merge.base_image_id, image.image_id);
          }
          base.CopyTo(shard_path);
        }
        FeatureExtractorOptions part = options;
        part.database_path = shard_path.string();
        part.shard = shard;
        mine = RunFeatureExtractor(part, progress);
      },
      remove_shard);
  const FeatureExtractorSummary total = SumOverRanks(mine);
  RunOnEveryRank(
      "feature_extractor",
      [&] {
        if (shard.index == 0) MergeShards(options, merge, total, &run);
      },
      remove_shard);
  remove_shard();
  LOG(INFO) << "feature_extractor: " << MpiWorld::Size() << " ranks: " << total.num_extracted
            << " images extracted (" << total.num_features << " features), " << total.num_skipped
            << " skipped, " << total.num_unreadable << " unreadable";
  return total;
}

}  // namespace

FeatureExtractorSummary RunFeatureExtractor(const FeatureExtractorOptions& options,
                                            ProgressSink& progress) {
  options.Check();
  if (options.shard.Whole() && MpiWorld::Distributed()) return RunOnRanks(options, progress);
  StageRun run("feature_extractor", OptionsText(options));
  const std::vector<std::string> names = options.shard.Block(ListImages(options.image_path));
  NewDatabaseFile new_file(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  Transaction transaction = database.BeginTransaction();

  // Rerun: images that have features already keep them, but their cameras
  // still meet the reader options first (an error naming the difference, or
  // with --ImageReader.overwrite the cameras imported again), before any
  // extraction.
  std::vector<std::string> todo;
  FeatureExtractorSummary summary;
  summary.num_images = static_cast<int>(names.size());
  SharedCameras shared_cameras;
  for (const std::string& name : names) {
    const std::optional<DatabaseImage> image = database.ReadImageWithName(name);
    if (image && !options.overwrite && database.ExistsKeypoints(image->image_id) &&
        database.ExistsDescriptors(image->image_id)) {
      const Camera camera = *database.ReadCamera(image->camera_id);
      ImportImage(&database, options.reader, name, static_cast<int>(camera.width),
                  static_cast<int>(camera.height), &shared_cameras);
      ++summary.num_skipped;
    } else {
      todo.push_back(name);
    }
  }
  LOG(INFO) << "feature_extractor: " << names.size() << " images, " << todo.size()
            << " to extract, " << summary.num_skipped << " already have features";

  std::vector<Extracted> slots(todo.size());
  progress.Begin("feature_extractor: images", todo.size());
  OrderedParallelFor(
      todo.size(), options.num_threads, 2 * static_cast<size_t>(options.num_threads) + 2,
      [&](size_t i) {
        const cv::Mat gray =
            cv::imread((fs::path(options.image_path) / todo[i]).string(), cv::IMREAD_GRAYSCALE);
        slots[i].skip_reason =
            gray.empty() ? "cannot read the image" : ImageSizeProblem(gray.cols, gray.rows);
        if (!slots[i].skip_reason.empty()) return;
        slots[i].readable = true;
        slots[i].width = gray.cols;
        slots[i].height = gray.rows;
        slots[i].features = ExtractSift(gray, options.sift);
      },
      [&](size_t i) {
        Extracted extracted = std::move(slots[i]);
        progress.Advance(1);
        if (!extracted.readable) {
          LOG(WARNING) << todo[i] << ": " << extracted.skip_reason << "; skipped";
          ++summary.num_unreadable;
          return;
        }
        const image_t image_id = ImportImage(&database, options.reader, todo[i], extracted.width,
                                             extracted.height, &shared_cameras);
        database.DeleteMatchesOfImage(image_id);
        database.DeleteUnmaskedFeatures(image_id);  // a mask starts from these now
        database.WriteKeypoints(image_id, extracted.features.keypoints);
        database.WriteDescriptors(image_id, extracted.features.descriptors);
        if (extracted.features.keypoints.empty()) LOG(WARNING) << todo[i] << ": no SIFT features";
        VLOG(1) << todo[i] << ": " << extracted.features.keypoints.size() << " features";
        ++summary.num_extracted;
        summary.num_features += static_cast<int64_t>(extracted.features.keypoints.size());
      });
  progress.End();
  if (options.shard.Whole())
    CheckSomethingExtracted(options, summary);  // a shard's block may be all unreadable
  run.Finish(&database, Counts(summary));
  CancelFlag::ThrowIfRequested();
  transaction.Commit();
  new_file.Keep();
  LOG(INFO) << "feature_extractor: " << summary.num_extracted << " images extracted ("
            << summary.num_features << " features), " << summary.num_skipped << " skipped, "
            << summary.num_unreadable << " unreadable";
  return summary;
}

}  // namespace portcal
