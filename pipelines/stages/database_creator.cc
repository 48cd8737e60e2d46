#include "pipelines/stages/database_creator.h"

#include <filesystem>

#include "colmap_ext/util/logging.h"
#include "database/database.h"

namespace portcal {

DatabaseCreatorSummary RunDatabaseCreator(const DatabaseCreatorOptions& options, ProgressSink& progress) {
  DatabaseCreatorSummary summary;
  summary.existed = std::filesystem::exists(options.database_path);
  Database database(options.database_path, Database::OpenMode::kCreate);
  summary.num_cameras = database.NumCameras();
  summary.num_images = database.NumImages();
  LOG(INFO) << (summary.existed ? "Checked existing database " : "Created database ")
            << options.database_path << ": " << summary.num_cameras << " cameras, "
            << summary.num_images << " images";
  return summary;
}

}  // namespace portcal
