// `portcal refractive_mapper`: incremental structure-from-motion on the
// database's verified matches, every observation a ray in water when the
// camera has a housing (portcal_housings, or --Housing.* for all cameras).
// When a camera has no prior focal length and ArUco markers were detected
// (feature_masker), the markers pre-calibrate its focal length. Writes one
// COLMAP sparse model per reconstructed component into output_path/0, /1,
// ... (binary, plus housings.txt), largest first.
#pragma once

#include <optional>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/sfm/model_mapping.h"

namespace portcal {

struct RefractiveMapperOptions : ModelMappingOptions {
  std::string database_path;
  std::string image_path;  // accepted for COLMAP compatibility
  std::string output_path;
  // COLMAP's --image_list_path: a file of image names, one per line; only
  // these images (and the pairs between them) are mapped. "": all.
  std::string image_list_path;
  void Check() const;  // throws OptionError naming the option
};

struct RefractiveMapperSummary {
  int num_models = 0;
  int num_registered = 0;  // over all models
  int num_images = 0;
  std::vector<std::filesystem::path> model_paths;
  std::vector<image_pair_t> initial_pairs;  // per model: the pair it grew from
  // Per model: its global adjustments that refined the intrinsics or housing.
  std::vector<std::vector<CalibrationRefinement>> calibration_refinements;
};

RefractiveMapperSummary RunRefractiveMapper(const RefractiveMapperOptions& options,
                                            ProgressSink& progress);

}  // namespace portcal
