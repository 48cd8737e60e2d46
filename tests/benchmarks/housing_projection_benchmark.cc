// Forward projection through a port: portcal's exact 1-D solve in the plane
// of refraction against a reference implementation of the refractive COLMAP
// fork's method (Gauss-Newton on the pixel, Jacobian by finite differences,
// each iteration = 5 back-projections, up to 100 iterations). Same points,
// same camera; read the two times as a ratio. The `max_diff_px` counter is
// the largest pixel difference between the two methods on the benchmark's
// points (equal accuracy), `max_error_px` each method's round-trip error.
// Last, the exact error as bundle adjustment evaluates it, with Jacobians.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <memory>
#include <random>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/camera/models/radial.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/housing/dome_port.h"
#include "colmap_ext/housing/flat_port.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {
namespace {

Camera BenchCamera() {
  Camera camera = Camera::FromModelName("RADIAL", 1297.3655, 1920, 1080);
  camera.params = {1297.3655, 960, 540, -0.05, 0.01};
  return camera;
}

Housing BenchHousing(bool dome) {
  if (dome) {
    return Housing::FromName("DOMEPORT", {0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334},
                             "bench");
  }
  const double tilt = 5.0 * M_PI / 180.0;
  return Housing::FromName(
      "FLATPORT", {std::sin(tilt), 0, std::cos(tilt), 0.02, 0.014, 1.0, 1.473, 1.334}, "bench");
}

// Points seen at known pixels: back-projected from a pixel grid at 0.4-3 m.
struct Sample {
  Eigen::Vector3d point;
  Eigen::Vector2d pixel;
};

std::vector<Sample> Samples(const Camera& camera, const Housing& housing) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(10, 1910), y(10, 1070), depth(0.4, 3.0);
  std::vector<Sample> samples;
  while (samples.size() < 1000) {
    const Eigen::Vector2d pixel(x(rng), y(rng));
    const auto ray = UnprojectPixel(camera, &housing, pixel);
    if (!ray) continue;
    samples.push_back({ray->origin + depth(rng) * ray->direction, pixel});
  }
  return samples;
}

// The fork's approach: start at the pinhole projection and move the pixel
// until its back-projected ray passes through the point. The residual is
// the point's offset from the ray, perpendicular to it; the Jacobian comes
// from central differences (4 more back-projections per iteration).
std::optional<Eigen::Vector2d> ProjectIterative(const Camera& camera, const Housing& housing,
                                                const Eigen::Vector3d& point) {
  std::optional<Eigen::Vector2d> start = camera.ImgFromCam(point);
  if (!start) return std::nullopt;
  Eigen::Vector2d pixel = *start;
  const auto residual = [&](const Eigen::Vector2d& px, Eigen::Vector2d* r) {
    const auto ray = UnprojectPixel(camera, &housing, px);
    if (!ray) return false;
    const Eigen::Vector3d offset = point - ray->origin;
    const Eigen::Vector3d perp = offset - offset.dot(ray->direction) * ray->direction;
    *r = perp.head<2>();
    return true;
  };
  constexpr double kStep = 1e-4;  // px
  for (int iter = 0; iter < 100; ++iter) {
    Eigen::Vector2d r, rp, rm;
    if (!residual(pixel, &r)) return std::nullopt;
    Eigen::Matrix2d jacobian;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d delta = Eigen::Vector2d::Zero();
      delta[k] = kStep;
      if (!residual(pixel + delta, &rp) || !residual(pixel - delta, &rm)) return std::nullopt;
      jacobian.col(k) = (rp - rm) / (2 * kStep);
    }
    const Eigen::Vector2d step = jacobian.colPivHouseholderQr().solve(-r);
    pixel += step;
    if (step.norm() < 1e-11) break;
  }
  return pixel;
}

void ProjectExact(benchmark::State& state, bool dome) {
  const Camera camera = BenchCamera();
  const Housing housing = BenchHousing(dome);
  const std::vector<Sample> samples = Samples(camera, housing);
  double max_error = 0, max_diff = 0;
  for (const Sample& s : samples) {
    const auto exact = ProjectPoint(camera, &housing, s.point);
    const auto iterative = ProjectIterative(camera, housing, s.point);
    if (!exact || !iterative) continue;
    max_error = std::max(max_error, (*exact - s.pixel).norm());
    max_diff = std::max(max_diff, (*exact - *iterative).norm());
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ProjectPoint(camera, &housing, samples[i++ % samples.size()].point));
  }
  state.counters["max_error_px"] = max_error;
  state.counters["max_diff_px"] = max_diff;
}

void ProjectReference(benchmark::State& state, bool dome) {
  const Camera camera = BenchCamera();
  const Housing housing = BenchHousing(dome);
  const std::vector<Sample> samples = Samples(camera, housing);
  double max_error = 0;
  for (const Sample& s : samples) {
    const auto iterative = ProjectIterative(camera, housing, s.point);
    if (iterative) max_error = std::max(max_error, (*iterative - s.pixel).norm());
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        ProjectIterative(camera, housing, samples[i++ % samples.size()].point));
  }
  state.counters["max_error_px"] = max_error;
}

// The bundle adjustment's inner loop: the exact refractive reprojection
// error (pose, point, intrinsics, housing all blocks: 23-wide Jets) with
// its Jacobians, on the same points seen from the identity pose.
void ReprojectionErrorWithJacobians(benchmark::State& state, bool dome) {
  const Camera camera = BenchCamera();
  const Housing housing = BenchHousing(dome);
  const std::vector<Sample> samples = Samples(camera, housing);
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const Sample& s : samples) {
    if (dome) {
      costs.emplace_back(RefractiveReprojError<RadialModel, DomePort>::Create(s.pixel, 1.0));
    } else {
      costs.emplace_back(RefractiveReprojError<RadialModel, FlatPort>::Create(s.pixel, 1.0));
    }
  }
  double pose[7] = {0, 0, 0, 1, 0, 0, 0};
  std::vector<double> intrinsics = camera.params, port = housing.params;
  double jacobian_storage[4][2 * 8];
  double* jacobians[4] = {jacobian_storage[0], jacobian_storage[1], jacobian_storage[2],
                          jacobian_storage[3]};
  double residual[2];
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ % samples.size();
    const double* blocks[4] = {pose, samples[k].point.data(), intrinsics.data(), port.data()};
    benchmark::DoNotOptimize(costs[k]->Evaluate(blocks, residual, jacobians));
  }
}

void BM_FlatPortProjectExact(benchmark::State& state) { ProjectExact(state, false); }
void BM_FlatPortProjectIterative(benchmark::State& state) { ProjectReference(state, false); }
void BM_DomePortProjectExact(benchmark::State& state) { ProjectExact(state, true); }
void BM_DomePortProjectIterative(benchmark::State& state) { ProjectReference(state, true); }

BENCHMARK(BM_FlatPortProjectExact);
BENCHMARK(BM_FlatPortProjectIterative);
BENCHMARK(BM_DomePortProjectExact);
BENCHMARK(BM_DomePortProjectIterative);
void BM_FlatPortErrorWithJacobians(benchmark::State& state) {
  ReprojectionErrorWithJacobians(state, false);
}
void BM_DomePortErrorWithJacobians(benchmark::State& state) {
  ReprojectionErrorWithJacobians(state, true);
}
BENCHMARK(BM_FlatPortErrorWithJacobians);
BENCHMARK(BM_DomePortErrorWithJacobians);

}  // namespace
}  // namespace portcal

BENCHMARK_MAIN();
