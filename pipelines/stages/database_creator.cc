#include "pipelines/stages/database_creator.h"

#include <filesystem>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/new_database_file.h"

namespace portcal {

DatabaseCreatorSummary RunDatabaseCreator(const DatabaseCreatorOptions& options,
                                          ProgressSink& progress) {
  DatabaseCreatorSummary summary;
  summary.existed = std::filesystem::exists(options.database_path);
  NewDatabaseFile new_file(options.database_path);  // a full disk leaves no half-made file
  {
    Database database(options.database_path, Database::OpenMode::kCreate,
                      options.colmap_version.value_or(ColmapVersion::k3_8));
    summary.num_cameras = database.NumCameras();
    summary.num_images = database.NumImages();
    summary.layout = database.layout().VersionRange();
    if (summary.existed && options.colmap_version &&
        NewestVersionWith(database.layout()) != *options.colmap_version &&
        summary.layout != LayoutOf(*options.colmap_version).VersionRange()) {
      throw InputError(
          options.database_path + ": an existing database of " + summary.layout +
          "'s layout, not " + "COLMAP " + ColmapVersionName(*options.colmap_version) +
          "'s (--Database.colmap_version); convert it with portcal database_converter");
    }
  }
  new_file.Keep();
  LOG(INFO) << (summary.existed ? "Checked existing database " : "Created database ")
            << options.database_path << " (" << summary.layout << "): " << summary.num_cameras
            << " cameras, " << summary.num_images << " images";
  return summary;
}

}  // namespace portcal
