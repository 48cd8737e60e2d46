// Fuzz target: the stereo calibration.yaml image_undistorter takes for
// rectified pairs (stereo_calibrator's cam2_from_cam1 and camera blocks),
// told from one camera's file as the stage does.
#include "pipelines/calibration/stereo_calibration_file.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile("calibration.yaml", data, size,
                                    [](const std::filesystem::path& path) {
                                      if (portcal::IsStereoCalibrationFile(path))
                                        portcal::ReadStereoCalibrationFile(path);
                                    });
}
