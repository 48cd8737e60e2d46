// Fuzz target: the rig and frame files of COLMAP 3.12+ models, the input's
// four parts as rigs.txt, frames.txt, rigs.bin and frames.bin, each read
// on its own (ReadSparseModel reads them beside the other files).
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = portcal::fuzz::SplitParts(data, size, 4);
  const auto rigs_text = portcal::fuzz::WriteFile("rigs.txt", parts[0]);
  const auto frames_text = portcal::fuzz::WriteFile("frames.txt", parts[1]);
  const auto rigs_binary = portcal::fuzz::WriteFile("rigs.bin", parts[2]);
  const auto frames_binary = portcal::fuzz::WriteFile("frames.bin", parts[3]);
  const auto read = [](const auto& reader, const std::filesystem::path& path) {
    try {
      reader(path);
    } catch (const portcal::InputError&) {
    }
  };
  read([](const auto& p) { return portcal::ReadRigsText(p); }, rigs_text);
  read([](const auto& p) { return portcal::ReadFramesText(p); }, frames_text);
  read([](const auto& p) { return portcal::ReadRigsBinary(p); }, rigs_binary);
  read([](const auto& p) { return portcal::ReadFramesBinary(p); }, frames_binary);
  return 0;
}
