// `portcal pose_prior_importer`: stores where navigation (DVL/INS, USBL,
// GPS) says each image's camera centre was, as position priors where the
// database's COLMAP version keeps them: images.prior_tx..tz with prior_q
// NULL in 3.8-3.9 (as COLMAP 3.8 stores EXIF GPS), pose_priors (Cartesian)
// from 3.10 on (docs/database.md). The refractive bundle adjuster takes
// a survey's metric scale from them (--PosePrior.position_sigma).
//
// The file has one image per line, "NAME X Y Z" (metres, a local Cartesian
// frame such as the survey's ENU or NED; not latitude/longitude), blank
// lines and lines starting with '#' ignored. One transaction: a malformed
// line or an unknown image name stores nothing.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>

#include "colmap_ext/util/progress.h"

namespace portcal {

struct PosePriorImporterOptions {
  std::string database_path;
  std::string input_path;  // the positions file
  void Check() const;      // throws OptionError naming the option
};

struct PosePriorImporterSummary {
  int num_imported = 0;
  int num_images_without = 0;  // database images the file does not list
};

// The positions of a file of "NAME X Y Z" lines ('#' comments, blank lines);
// throws InputError naming the file and line.
std::map<std::string, Eigen::Vector3d> ReadPositionsFile(const std::string& path);

PosePriorImporterSummary RunPosePriorImporter(const PosePriorImporterOptions& options,
                                              ProgressSink& progress);

}  // namespace portcal
