// Fuzz target: OpenCV FileStorage and ROS camera_info YAML files.
#include "colmap_ext/io/opencv_camera_file.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return portcal::fuzz::ParseAsFile("camera.yaml", data, size,
                                    [](const std::filesystem::path& path) {
                                      portcal::IsOpenCvOrRosCameraYaml(path);
                                      portcal::ReadOpenCvCameraYaml(path);
                                    });
}
