#include "pipelines/stages/pose_prior_importer.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"
#include "database/stage_run.h"

namespace portcal {

void PosePriorImporterOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "an existing database");
  if (!std::filesystem::is_regular_file(database_path)) {
    throw OptionError("--database_path", database_path,
                      "an existing database (run feature_extractor first)");
  }
  if (input_path.empty()) throw OptionError("--input_path", "''", "a file of 'NAME X Y Z' lines");
}

std::map<std::string, Eigen::Vector3d> ReadPositionsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  std::map<std::string, Eigen::Vector3d> positions;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string where = path + ":" + std::to_string(line_number);
    std::istringstream fields(line);
    std::string name;
    if (!(fields >> name) || name[0] == '#') continue;
    Eigen::Vector3d xyz;
    std::string extra;
    if (!(fields >> xyz.x() >> xyz.y() >> xyz.z()) || (fields >> extra)) {
      throw InputError(where + ": expected 'NAME X Y Z', got '" + line + "'");
    }
    if (!xyz.allFinite()) throw InputError(where + ": position of '" + name + "' is not finite");
    if (!positions.emplace(name, xyz).second)
      throw InputError(where + ": '" + name + "' listed twice");
  }
  if (positions.empty()) throw InputError(path + ": no 'NAME X Y Z' line");
  return positions;
}

PosePriorImporterSummary RunPosePriorImporter(const PosePriorImporterOptions& options,
                                              ProgressSink& progress) {
  options.Check();
  const std::map<std::string, Eigen::Vector3d> positions = ReadPositionsFile(options.input_path);
  StageRun run("pose_prior_importer", "input_path=" + options.input_path + "\n");
  Database database(options.database_path, Database::OpenMode::kReadWrite);
  Transaction transaction = database.BeginTransaction();
  std::map<std::string, image_t> ids;
  for (const DatabaseImage& image : database.ReadAllImages()) ids[image.name] = image.image_id;
  PosePriorImporterSummary summary;
  for (const auto& [name, xyz] : positions) {
    const auto it = ids.find(name);
    if (it == ids.end()) {
      throw InputError(options.input_path + ": image '" + name + "' is not in " +
                       options.database_path);
    }
    database.UpdatePositionPrior(it->second, xyz);
    ++summary.num_imported;
  }
  summary.num_images_without = static_cast<int>(ids.size()) - summary.num_imported;
  run.Finish(&database,
             {{"imported", summary.num_imported}, {"images_without", summary.num_images_without}});
  transaction.Commit();
  LOG(INFO) << "pose_prior_importer: " << summary.num_imported << " position priors stored; "
            << summary.num_images_without << " image(s) without one";
  if (summary.num_images_without > 0) {
    LOG(WARNING) << "pose_prior_importer: " << summary.num_images_without << " image(s) of "
                 << options.database_path << " are not in " << options.input_path
                 << " and keep no prior";
  }
  return summary;
}

}  // namespace portcal
