// `portcal model_converter`: COLMAP sparse models between .bin and .txt, with
// the housings.txt sidecar; reads the refractive fork's cameras.txt too.
#pragma once

#include <string>

namespace portcal {

struct ModelConverterOptions {
  std::string input_path;   // directory with a sparse model
  std::string output_path;  // directory to write (created if missing)
  std::string output_type = "BIN";  // BIN | TXT

  void Check() const;  // throws OptionError naming the option
};

// Returns a one-line summary of what was converted.
std::string ConvertModel(const ModelConverterOptions& options);

}  // namespace portcal
