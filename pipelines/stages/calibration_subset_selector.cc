#include "pipelines/stages/calibration_subset_selector.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "colmap_ext/util/confined_path.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "database/database.h"

namespace fs = std::filesystem;

namespace portcal {

void CalibrationSubsetSelectorOptions::Check() const {
  if (database_path.empty()) throw OptionError("--database_path", "''", "a matched database");
  if (output_path.empty()) throw OptionError("--output_path", "''", "the image list to write");
  const fs::path folder = fs::path(output_path).parent_path();
  if (!folder.empty() && !fs::is_directory(folder)) {
    throw OptionError("--output_path", output_path, "a file in an existing folder");
  }
  CheckOutputFile("--output_path", output_path, {database_path});
  subset.Check();
}

CalibrationSubsetSelectorSummary RunCalibrationSubsetSelector(
    const CalibrationSubsetSelectorOptions& options, ProgressSink& progress) {
  options.Check();
  Database database(options.database_path, Database::OpenMode::kReadOnly);
  std::vector<DatabaseImage> images = database.ReadAllImages();
  std::sort(images.begin(), images.end(),
            [](const DatabaseImage& a, const DatabaseImage& b) { return a.name < b.name; });
  std::vector<image_t> ordered;
  std::map<image_t, std::string> names;
  for (const DatabaseImage& image : images) {
    ordered.push_back(image.image_id);
    names[image.image_id] = image.name;
  }
  progress.Begin("calibration_subset_selector: verified pairs", 1);
  std::map<image_pair_t, int> inliers;
  for (const auto& [pair_id, geometry] : database.ReadTwoViewGeometries()) {
    if (!geometry.inlier_matches.empty())
      inliers[pair_id] = static_cast<int>(geometry.inlier_matches.size());
  }
  progress.Advance(1);
  progress.End();
  if (inliers.empty())
    throw InputError(options.database_path + ": no verified image pairs; run a matcher first");
  const CalibrationSubset subset = ChooseCalibrationSubset(ordered, inliers, options.subset);

  // Written beside and renamed: a failed write leaves no partial list.
  const fs::path partial = options.output_path + ".partial";
  {
    std::ofstream list(partial);
    for (image_t id : subset.images) list << names.at(id) << "\n";
    if (!list.flush()) {
      std::error_code ignored;
      fs::remove(partial, ignored);
      throw InputError(options.output_path + ": cannot write the image list");
    }
  }
  fs::rename(partial, options.output_path);
  CalibrationSubsetSelectorSummary summary;
  summary.num_images = static_cast<int>(ordered.size());
  summary.num_selected = static_cast<int>(subset.images.size());
  summary.num_breaks = subset.num_breaks;
  LOG(INFO) << "calibration_subset_selector: " << summary.num_selected << " of "
            << summary.num_images << " images -> " << options.output_path;
  if (subset.num_breaks > 0) {
    LOG(WARNING)
        << "calibration_subset_selector: " << subset.num_breaks
        << " place(s) where no later image shares " << options.subset.min_num_inliers
        << " verified inliers with the last kept one: the subset may map as several models "
           "(lower --Subset.min_num_inliers, or match more pairs)";
  }
  return summary;
}

}  // namespace portcal
