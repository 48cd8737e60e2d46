// Fuzz target: mrcal's .cameramodel files (a Python-literal dict), as
// --input_calibration and model_converter read them.
#include "colmap_ext/io/mrcal_model.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile("camera.cameramodel", data, size, [](const std::filesystem::path& path) {
    portcal::ReadMrcalCameraModel(path);
  });
}
