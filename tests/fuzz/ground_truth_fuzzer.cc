// Fuzz target: ground_truth.yaml of rendered sets (../shared's and
// synthesize's), which the accuracy tools and tests read.
#include "colmap_ext/io/ground_truth.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile(
      "ground_truth.yaml", data, size,
      [](const std::filesystem::path& path) { portcal::ReadGroundTruth(path); });
}
