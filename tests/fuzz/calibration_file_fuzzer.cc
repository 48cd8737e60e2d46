// Fuzz target: the calibration files --input_calibration takes (portcal's and
// calibmar's calibration.yaml, OpenCV's and ROS's camera YAML), told apart
// by their content as the reader does. Errors must be portcal's (naming the
// file); anything else escaping is a finding.
#include "pipelines/calibration/calibration_report.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile(
      "calibration.yaml", data, size,
      [](const std::filesystem::path& path) { portcal::ReadCalibrationReport(path); });
}
