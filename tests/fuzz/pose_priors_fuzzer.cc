// Fuzz target: pose_prior_importer's "NAME X Y Z" files.
#include "pipelines/stages/pose_prior_importer.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile(
      "priors.txt", data, size,
      [](const std::filesystem::path& path) { portcal::ReadPositionsFile(path.string()); });
}
