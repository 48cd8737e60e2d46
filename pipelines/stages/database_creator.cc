#include "pipelines/stages/database_creator.h"

#include <filesystem>

#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/new_database_file.h"

namespace portcal {

DatabaseCreatorSummary RunDatabaseCreator(const DatabaseCreatorOptions& options, ProgressSink& progress) {
  DatabaseCreatorSummary summary;
  summary.existed = std::filesystem::exists(options.database_path);
  NewDatabaseFile new_file(options.database_path);  // a full disk leaves no half-made file
  {
    Database database(options.database_path, Database::OpenMode::kCreate);
    summary.num_cameras = database.NumCameras();
    summary.num_images = database.NumImages();
  }
  new_file.Keep();
  LOG(INFO) << (summary.existed ? "Checked existing database " : "Created database ")
            << options.database_path << ": " << summary.num_cameras << " cameras, "
            << summary.num_images << " images";
  return summary;
}

}  // namespace portcal
