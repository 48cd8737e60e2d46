#include "pipelines/stages/refractive_mapper.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <string>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"

namespace fs = std::filesystem;

namespace portcal {

void RefractiveMapperOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a database file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "a directory for the models");
  CheckOutputFolder("--output_path", output_path);
  ModelMappingOptions::Check();
}

namespace {

// The names of --image_list_path, each checked against the database.
std::set<std::string> ReadImageList(const std::string& path, Database* database) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot read the image list (--image_list_path)");
  std::set<std::string> names;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    const size_t begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    const std::string name = line.substr(begin, line.find_last_not_of(" \t\r") + 1 - begin);
    if (!database->ReadImageWithName(name)) {
      throw InputError(path + ":" + std::to_string(number) + ": image '" + name + "' is not in " +
                       database->path());
    }
    names.insert(name);
  }
  if (names.empty()) throw InputError(path + ": no image names (--image_list_path)");
  return names;
}

SfmInputs ReadInputs(const RefractiveMapperOptions& options) {
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  if (options.image_list_path.empty()) return SfmInputs::Read(&database);
  const std::set<std::string> names = ReadImageList(options.image_list_path, &database);
  LOG(INFO) << "refractive_mapper: " << names.size() << " images of " << options.image_list_path;
  return SfmInputs::Read(&database, &names);
}

}  // namespace

RefractiveMapperSummary RunRefractiveMapper(const RefractiveMapperOptions& options,
                                            ProgressSink& progress) {
  options.Check();
  NewPaths new_output({options.output_path});  // a failed run leaves no output folder it made
  const SfmInputs inputs = ReadInputs(options);
  if (inputs.pair_inliers.empty()) {
    throw InputError(options.database_path + ": no verified image pairs; run a matcher first");
  }
  if (options.mapper.position_prior_sigma_m > 0 &&
      std::none_of(inputs.images.begin(), inputs.images.end(),
                   [](const auto& entry) { return entry.second.position_prior.has_value(); })) {
    throw InputError(options.database_path +
                     ": no image has a position prior, so --PosePrior.position_sigma "
                     "has nothing to use (run pose_prior_importer, or set it to 0)");
  }
  const std::vector<MappedModel> models = MapModels(inputs, options, progress);
  RefractiveMapperSummary summary;
  summary.num_images = static_cast<int>(inputs.images.size());
  for (size_t m = 0; m < models.size(); ++m) {
    const fs::path dir = fs::path(options.output_path) / std::to_string(m);
    WriteSparseModel(models[m].reconstruction.ToSparseModel(), dir, ModelFormat::kBinary);
    summary.model_paths.push_back(dir);
    summary.initial_pairs.push_back(models[m].initial_pair);
    summary.num_registered += static_cast<int>(models[m].reconstruction.poses().size());
    const auto& refinements = models[m].calibration_refinements;
    const auto held = std::find_if(refinements.begin(), refinements.end(),
                                   [](const CalibrationRefinement& c) { return c.settled; });
    summary.calibration_refinements.push_back(refinements);
    if (held != refinements.end()) {
      LOG(INFO) << "refractive_mapper: model " << m << ": intrinsics and housing held from "
                << held->num_images << " images on (that refinement moved the image by "
                << held->image_shift_px << " px), refined again at the end";
    }
  }
  summary.num_models = static_cast<int>(models.size());
  LOG(INFO) << "refractive_mapper: " << summary.num_models << " model(s), "
            << summary.num_registered << " of " << summary.num_images
            << " images registered; written to " << options.output_path;
  new_output.Keep();
  return summary;
}

}  // namespace portcal
