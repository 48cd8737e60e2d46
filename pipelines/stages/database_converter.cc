#include "pipelines/stages/database_converter.h"

#include <filesystem>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/new_database_file.h"

namespace portcal {

void DatabaseConverterOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "the database to convert");
  if (!output_path.empty() && std::filesystem::exists(output_path)) {
    throw OptionError("--output_path", output_path, "a file that does not exist yet (the converted copy)");
  }
}

DatabaseConverterSummary RunDatabaseConverter(const DatabaseConverterOptions& options, ProgressSink& progress) {
  options.Check();
  DatabaseConverterSummary summary;
  std::string path = options.database_path;
  NewDatabaseFile new_copy(options.output_path.empty() ? options.database_path : options.output_path);
  if (!options.output_path.empty()) {
    Database source(options.database_path, Database::OpenMode::kReadOnly);
    source.CopyTo(options.output_path);
    path = options.output_path;
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
  new_copy.Keep();
  LOG(INFO) << path << ": converted from " << summary.from << "'s layout to " << summary.to << "'s ("
            << summary.num_images << " images)";
  return summary;
}

}  // namespace portcal
