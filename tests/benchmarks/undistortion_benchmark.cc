// image_undistorter's two costs: the remap tables, computed once per camera
// (exact refraction per pixel, on 1 and 2 threads), and applying them to a
// 1920 x 1080 image on one core (the bound: 10 ms), gray and
// colour, with the float tables portcal applies (and writes) against
// their fixed-point form (cv::convertMaps), which OpenCV suggests for speed.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "colmap_ext/util/progress.h"
#include "pipelines/undistortion/remap_tables.h"

namespace portcal {
namespace {

VirtualPinhole BenchPinhole(bool dome) {
  Camera camera = Camera::FromModelName("OPENCV", 1300, 1920, 1080);
  camera.params = {1300, 1296, 975.5, 528.0, -0.12, 0.05, 0.0007, -0.0004};
  const double tilt = 5.0 * M_PI / 180.0;
  const Housing housing =
      dome ? Housing::FromName("DOMEPORT", {0.002, -0.001, 0.004, 0.05, 0.006, 1.0, 1.473, 1.334},
                               "b")
           : Housing::FromName("FLATPORT",
                               {std::sin(tilt), 0, std::cos(tilt), 0.02, 0.014, 1.0, 1.473, 1.334},
                               "b");
  return FitVirtualPinhole({camera, housing}, 2.0, Eigen::Matrix3d::Identity(), {});
}

void BM_ComputeRemapTables(benchmark::State& state) {
  const VirtualPinhole pinhole = BenchPinhole(state.range(0) == 1);
  NullProgress progress;
  for (auto _ : state) {
    RemapTables tables = ComputeRemapTables(pinhole, static_cast<int>(state.range(1)), progress);
    benchmark::DoNotOptimize(tables.map_x.data);
  }
  state.SetLabel(std::string(state.range(0) == 1 ? "dome" : "flat") + ", " +
                 std::to_string(state.range(1)) + " threads, " +
                 std::to_string(pinhole.pinhole.width) + " x " +
                 std::to_string(pinhole.pinhole.height));
}
BENCHMARK(BM_ComputeRemapTables)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

cv::Mat BenchImage(int channels) {
  cv::Mat image(1080, 1920, CV_8UC(channels));
  cv::randu(image, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.5);
  return image;
}

// Args: channels, fixed-point (1) or float (0) tables.
void BM_ApplyRemapTables(benchmark::State& state) {
  cv::setNumThreads(0);  // one core, as the bound asks
  const VirtualPinhole pinhole = BenchPinhole(false);
  NullProgress progress;
  const RemapTables tables = ComputeRemapTables(pinhole, 2, progress);
  const cv::Mat image = BenchImage(static_cast<int>(state.range(0)));
  const bool fixed = state.range(1) == 1;
  cv::Mat fixed_xy, fixed_fraction, output;
  cv::convertMaps(tables.map_x, tables.map_y, fixed_xy, fixed_fraction, CV_16SC2);
  for (auto _ : state) {
    if (fixed) {
      cv::remap(image, output, fixed_xy, fixed_fraction, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                cv::Scalar::all(0));
    } else {
      output = ApplyRemapTables(tables, image, image.size());
    }
    benchmark::DoNotOptimize(output.data);
  }
  state.SetLabel(std::string(state.range(0) == 1 ? "gray" : "colour") +
                 (fixed ? ", fixed-point" : ", float") + " tables, 1 thread");
  cv::setNumThreads(-1);
}
BENCHMARK(BM_ApplyRemapTables)
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({3, 1})
    ->Args({3, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace portcal

BENCHMARK_MAIN();
