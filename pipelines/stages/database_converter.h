// `portcal database_converter`: a database moved to another COLMAP
// version's layout (3.8 to 4.1, up or down), as that version's own
// migration would move it, without losing a row (Database::ConvertTo);
// in place, or into a converted copy with --output_path.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"
#include "database/colmap_layout.h"

namespace portcal {

struct DatabaseConverterOptions {
  std::string database_path;
  std::string output_path;  // "": convert in place
  ColmapVersion colmap_version = ColmapVersion::k3_8;

  void Check() const;  // throws OptionError naming the option
};

struct DatabaseConverterSummary {
  std::string from, to;  // e.g. "COLMAP 3.8", "COLMAP 4.1"
  int64_t num_images = 0;
};

// Throws InputError (the rows the target cannot hold, named) or
// DatabaseError; either way nothing changes: the conversion is one
// transaction and a copy that failed is removed.
DatabaseConverterSummary RunDatabaseConverter(const DatabaseConverterOptions& options,
                                              ProgressSink& progress);

}  // namespace portcal
