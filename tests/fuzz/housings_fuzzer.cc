// Fuzz target: housings.txt, and the refractive fork's cameras.txt (the
// housing after the camera's parameters) that model_converter imports.
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = portcal::fuzz::WriteFile(
      "housings.txt", std::string(reinterpret_cast<const char*>(data), size));
  try {
    portcal::ReadHousingsText(path);
  } catch (const portcal::InputError&) {
  }
  try {
    std::map<portcal::camera_t, portcal::Camera> cameras;
    std::map<portcal::camera_t, portcal::Housing> housings;
    portcal::ImportRefractiveCamerasText(path, &cameras, &housings);
  } catch (const portcal::InputError&) {
  }
  return 0;
}
