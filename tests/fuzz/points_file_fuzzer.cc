// Fuzz target: project_points' point files ("X Y Z" or, unprojecting,
// "x y" lines), through a camera behind a flat port; the first byte picks
// the direction.
#include "colmap_ext/util/error.h"
#include "pipelines/stages/project_points.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  portcal::ProjectPointsOptions options;
  options.camera_model = "OPENCV";
  options.camera_params = "800,790,320.5,240.5,-0.1,0.02,0.001,-0.001";
  options.width = 640;
  options.height = 480;
  options.housing =
      portcal::Housing::FromName("FLATPORT", {0, 0, 1, 0.01, 0.005, 1.0, 1.49, 1.333}, "fuzz");
  options.unproject = data[0] & 1;
  options.points_path =
      portcal::fuzz::WriteFile("points.txt",
                               std::string(reinterpret_cast<const char*>(data + 1), size - 1))
          .string();
  portcal::NullProgress progress;
  try {
    portcal::RunProjectPoints(options, progress);
  } catch (const portcal::InputError&) {
  }
  return 0;
}
