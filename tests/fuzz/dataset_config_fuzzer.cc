// Fuzz target: synthesize's dataset configs (--config).
#include "pipelines/synthetic/dataset_config.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile(
      "config.yaml", data, size,
      [](const std::filesystem::path& path) { portcal::ReadDatasetConfig(path); });
}
