#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "colmap_ext/util/progress.h"
#include "database/colmap_layout.h"

namespace portcal {

struct DatabaseCreatorOptions {
  std::string database_path;
  // The layout of a new database (none: 3.8, Debian 12's COLMAP); for an
  // existing one, the layout it must have.
  std::optional<ColmapVersion> colmap_version;
};

struct DatabaseCreatorSummary {
  bool existed = false;  // an existing database was checked, not created
  int64_t num_cameras = 0, num_images = 0;
  std::string layout;  // e.g. "COLMAP 3.12-3.13"
};

// Creates a database of `colmap_version`'s layout with portcal's tables at
// `database_path`, or checks an existing one (as `colmap database_creator`
// does). Throws DatabaseError, and InputError for an existing database of
// another layout than the one asked for (database_converter converts).
DatabaseCreatorSummary RunDatabaseCreator(const DatabaseCreatorOptions& options,
                                          ProgressSink& progress);

}  // namespace portcal
