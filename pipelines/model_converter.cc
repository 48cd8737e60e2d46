#include "pipelines/model_converter.h"

#include <filesystem>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

void ModelConverterOptions::Check() const {
  if (input_path.empty()) throw OptionError("--input_path", "''", "a model directory");
  if (output_path.empty()) {
    throw OptionError("--output_path", "''", "an output directory");
  }
  if (output_type != "BIN" && output_type != "TXT") {
    throw OptionError("--output_type", output_type, "BIN or TXT");
  }
}

std::string ConvertModel(const ModelConverterOptions& options) {
  options.Check();
  const SparseModel model = ReadSparseModel(options.input_path);
  WriteSparseModel(model, options.output_path,
                   options.output_type == "BIN" ? ModelFormat::kBinary
                                                : ModelFormat::kText);
  const std::string summary =
      std::to_string(model.cameras.size()) + " cameras, " +
      std::to_string(model.images.size()) + " images, " +
      std::to_string(model.points3D.size()) + " points, " +
      std::to_string(model.housings.size()) + " housings written as " +
      options.output_type + " to " + options.output_path;
  LOG(INFO) << summary;
  return summary;
}

}  // namespace portcal
