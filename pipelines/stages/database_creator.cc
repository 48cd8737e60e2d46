#include "pipelines/stages/database_creator.h"

#include "colmap_ext/util/logging.h"
#include "database/database.h"

namespace portcal {

void CreateDatabase(const std::filesystem::path& path) {
  const bool existed = std::filesystem::exists(path);
  Database database(path, Database::OpenMode::kCreate);
  LOG(INFO) << (existed ? "Checked existing database " : "Created database ")
            << path.string() << ": " << database.NumCameras() << " cameras, "
            << database.NumImages() << " images";
}

}  // namespace portcal
