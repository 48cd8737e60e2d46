// The brute-force nearest-descriptor search of one image pair at a survey
// image's feature count (~4300 features each): the portable Eigen product
// and scan against the AVX2 tiles. Read the two times as a ratio; the
// `gflops` counter counts the 2 x n1 x n2 x 128 multiply-adds' flops.
#include <benchmark/benchmark.h>

#include <random>

#include "pipelines/features/nearest_descriptors.h"

namespace portcal {
namespace {

UnitDescriptorRows Descriptors(int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 40);
  std::uniform_int_distribution<int> spike(0, 9);
  UnitDescriptorRows d(rows, 128);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 128; ++c)
      d(r, c) = static_cast<float>(byte(rng) + (spike(rng) == 0 ? 120 : 0));
    d.row(r).normalize();
  }
  return d;
}

template <bool kAvx2>
void BM_NearestDescriptors(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const UnitDescriptorRows a = Descriptors(n, 1), b = Descriptors(n, 2);
  std::vector<NearestDescriptors> n1, n2;
  for (auto _ : state) {
    if (kAvx2) {
      if (!FindNearestDescriptorsAvx2(a, b, &n1, &n2)) {
        state.SkipWithError("this CPU has no AVX2 + FMA");
        break;
      }
    } else {
      FindNearestDescriptorsPortable(a, b, &n1, &n2);
    }
    benchmark::DoNotOptimize(n1.data());
  }
  state.counters["gflops"] =
      benchmark::Counter(2.0 * n * n * 128, benchmark::Counter::kIsIterationInvariantRate,
                         benchmark::Counter::kIs1000);
}

BENCHMARK_TEMPLATE(BM_NearestDescriptors, false)->Arg(4300)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_NearestDescriptors, true)->Arg(4300)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace portcal

BENCHMARK_MAIN();
