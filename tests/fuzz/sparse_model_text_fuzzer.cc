// Fuzz target: a text sparse model (cameras.txt, images.txt, points3D.txt
// and housings.txt, the input's four parts), read as a folder with the
// cross-file checks, as refractive_bundle_adjuster and model_converter do.
#include <filesystem>

#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = portcal::fuzz::SplitParts(data, size, 4);
  std::filesystem::create_directories(portcal::fuzz::WorkFolder() / "text");
  portcal::fuzz::WriteFile("text/cameras.txt", parts[0]);
  portcal::fuzz::WriteFile("text/images.txt", parts[1]);
  portcal::fuzz::WriteFile("text/points3D.txt", parts[2]);
  const auto housings = portcal::fuzz::WriteFile("text/housings.txt", parts[3]);
  if (parts[3].empty()) std::filesystem::remove(housings);
  try {
    portcal::ReadSparseModel(portcal::fuzz::WorkFolder() / "text");
  } catch (const portcal::InputError&) {
  }
  return 0;
}
