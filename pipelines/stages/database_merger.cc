#include "pipelines/stages/database_merger.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <vector>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/database_merge.h"
#include "database/integrity_check.h"
#include "database/new_database_file.h"
#include "database/stage_run.h"

namespace fs = std::filesystem;

namespace portcal {

void DatabaseMergerOptions::Check() const {
  if (database_path1.empty()) throw OptionError("--database_path1", "''", "the first database");
  if (database_path2.empty()) throw OptionError("--database_path2", "''", "the second database");
  if (merged_database_path.empty()) throw OptionError("--merged_database_path", "''", "a new file");
  if (fs::exists(merged_database_path)) {
    throw OptionError("--merged_database_path", merged_database_path,
                      "a file that does not exist yet");
  }
  std::error_code ignored;
  if (fs::equivalent(database_path1, database_path2, ignored)) {
    throw OptionError("--database_path2", database_path2, "another database than --database_path1");
  }
}

namespace {

// Both databases' images by name: a merged database would hold them twice.
void CheckNoNameInBoth(Database* first, Database* second) {
  std::set<std::string> names;
  for (const DatabaseImage& image : first->ReadAllImages()) names.insert(image.name);
  std::vector<std::string> both;
  for (const DatabaseImage& image : second->ReadAllImages()) {
    if (names.count(image.name)) both.push_back(image.name);
  }
  if (both.empty()) return;
  std::string listed;
  for (size_t i = 0; i < std::min<size_t>(both.size(), 3); ++i) listed += (i ? ", " : "") + both[i];
  throw InputError(first->path() + " and " + second->path() + ": " + std::to_string(both.size()) +
                   " image names are in both (" + listed + (both.size() > 3 ? ", ..." : "") +
                   "); a merged database would hold them twice");
}

}  // namespace

DatabaseMergerSummary RunDatabaseMerger(const DatabaseMergerOptions& options,
                                        ProgressSink& progress) {
  options.Check();
  CheckDatabaseIntegrity(options.database_path1);
  CheckDatabaseIntegrity(options.database_path2);
  {
    Database first(options.database_path1, Database::OpenMode::kReadOnly);
    Database second(options.database_path2, Database::OpenMode::kReadOnly);
    CheckNoNameInBoth(&first, &second);
  }
  StageRun run("database_merger", "database_path1=" + options.database_path1 +
                                      "\ndatabase_path2=" + options.database_path2 + "\n");
  // Made under a staging name and renamed when complete: a killed merge
  // leaves no file that looks like the merged database.
  const fs::path staging = options.merged_database_path + ".merging";
  fs::remove(staging);
  NewDatabaseFile new_file(staging);
  {
    Database first(options.database_path1, Database::OpenMode::kReadOnly);
    first.CopyTo(staging);
  }
  DatabaseMergerSummary summary;
  {
    Database second(options.database_path2, Database::OpenMode::kReadOnly);
    Database merged(staging, Database::OpenMode::kReadWrite);
    Transaction transaction = merged.BeginTransaction();
    progress.Begin("database_merger: " + options.database_path2, 1);
    const MergeSummary merge = MergeDatabase(&second, &merged, MergeOptions());
    progress.Advance(1);
    progress.End();
    summary.num_cameras = static_cast<int64_t>(merge.cameras.size());
    summary.num_images = static_cast<int64_t>(merge.images.size());
    summary.num_pairs = merge.num_pairs;
    run.Finish(&merged, {{"cameras", summary.num_cameras},
                         {"images", summary.num_images},
                         {"pairs", summary.num_pairs}});
    CancelFlag::ThrowIfRequested();
    transaction.Commit();
  }
  fs::rename(staging, options.merged_database_path);
  new_file.Keep();
  LOG(INFO) << "database_merger: " << options.database_path2 << "'s " << summary.num_cameras
            << " cameras, " << summary.num_images << " images and " << summary.num_pairs
            << " pairs after " << options.database_path1 << "'s -> "
            << options.merged_database_path;
  return summary;
}

}  // namespace portcal
