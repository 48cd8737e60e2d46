// `portcal database_merger`: two databases into a third, as `colmap
// database_merger` does (the same options): the first database's rows as
// they are, then the second's cameras and images with new ids after them
// and every row about them (database_merge.h: features, matches,
// geometries, pose priors' positions, and portcal's housings, target observations,
// detections, markers and unmasked features) in the first's COLMAP
// layout. An image name in both is refused.
#pragma once

#include <string>

#include "colmap_ext/util/progress.h"

namespace portcal {

struct DatabaseMergerOptions {
  std::string database_path1;
  std::string database_path2;
  std::string merged_database_path;  // a new file
  void Check() const;                // throws OptionError naming the option
};

struct DatabaseMergerSummary {
  int64_t num_cameras = 0, num_images = 0, num_pairs = 0;  // from the second database
};

// Throws InputError or DatabaseError; the merged file is then not made.
DatabaseMergerSummary RunDatabaseMerger(const DatabaseMergerOptions& options,
                                        ProgressSink& progress);

}  // namespace portcal
