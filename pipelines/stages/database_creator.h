#pragma once

#include <cstdint>
#include <string>

#include "colmap_ext/util/progress.h"

namespace portcal {

struct DatabaseCreatorOptions {
  std::string database_path;
};

struct DatabaseCreatorSummary {
  bool existed = false;  // an existing database was checked, not created
  int64_t num_cameras = 0, num_images = 0;
};

// Creates a COLMAP 3.8 database with portcal's tables at `database_path`, or
// checks an existing one (as `colmap database_creator` does). Throws
// DatabaseError.
DatabaseCreatorSummary RunDatabaseCreator(const DatabaseCreatorOptions& options, ProgressSink& progress);

}  // namespace portcal
