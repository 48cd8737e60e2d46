#include "pipelines/stages/database_converter.h"

#include <filesystem>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/integrity_check.h"
#include "database/new_database_file.h"

namespace portcal {

void DatabaseConverterOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "the database to convert");
  if (!output_path.empty() && std::filesystem::exists(output_path)) {
    throw OptionError("--output_path", output_path,
                      "a file that does not exist yet (the converted copy)");
  }
}

DatabaseConverterSummary RunDatabaseConverter(const DatabaseConverterOptions& options,
                                              ProgressSink& progress) {
  options.Check();
  CheckDatabaseIntegrity(options.database_path);
  DatabaseConverterSummary summary;
  // A copy is made under a staging name and renamed when converted, as
  // database_merger does: a killed run leaves no file under the output's
  // name (which a rerun would refuse), only a staging file the rerun
  // replaces.
  const std::string staging =
      options.output_path.empty() ? "" : options.output_path + ".converting";
  std::string path = options.database_path;
  if (!staging.empty()) {
    std::filesystem::remove(staging);
    path = staging;
  }
  NewDatabaseFile new_copy(path);
  if (!staging.empty()) {
    Database source(options.database_path, Database::OpenMode::kReadOnly);
    source.CopyTo(staging);
  }
  {
    Database database(path, Database::OpenMode::kReadWrite);
    summary.from = database.layout().VersionRange();
    summary.num_images = database.NumImages();
    progress.Begin("convert to COLMAP " + ColmapVersionName(options.colmap_version), 1);
    database.ConvertTo(options.colmap_version);
    progress.Advance(1);
    progress.End();
    summary.to = database.layout().VersionRange();
  }
  if (!staging.empty()) {
    std::filesystem::rename(staging, options.output_path);
    path = options.output_path;
  }
  new_copy.Keep();
  LOG(INFO) << path << ": converted from " << summary.from << "'s layout to " << summary.to
            << "'s (" << summary.num_images << " images)";
  return summary;
}

}  // namespace portcal
