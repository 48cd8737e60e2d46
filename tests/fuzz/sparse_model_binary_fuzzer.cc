// Fuzz target: a binary sparse model (cameras.bin, images.bin, points3D.bin,
// the input's three parts), read as a folder.
#include <filesystem>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = portcal::fuzz::SplitParts(data, size, 3);
  std::filesystem::create_directories(portcal::fuzz::WorkFolder() / "binary");
  portcal::fuzz::WriteFile("binary/cameras.bin", parts[0]);
  portcal::fuzz::WriteFile("binary/images.bin", parts[1]);
  portcal::fuzz::WriteFile("binary/points3D.bin", parts[2]);
  try {
    portcal::ReadSparseModel(portcal::fuzz::WorkFolder() / "binary");
  } catch (const portcal::InputError&) {
  }
  return 0;
}
