// Fuzz target: mrcal's .cameramodel files (a Python-literal dict), as
// --input_calibration and model_converter read them, and the solve they
// may keep (base 85 of an .npz archive), as housing_calibrator reads it.
#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/mrcal_optimization_inputs.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile(
      "camera.cameramodel", data, size, [](const std::filesystem::path& path) {
        const portcal::MrcalCameraModelFile file = portcal::ReadMrcalCameraModel(path);
        if (!file.optimization_inputs_base85.empty())
          portcal::ReadMrcalBoardSolve(file, path.string());
      });
}
