// Geometric verification of one calibrated pair (900 matches, 30 % chance
// ones, 0.5 px noise) against its last part, the relative pose's fit to
// E's inliers (relative_pose_refinement.h): read the two times as the
// share of verification the fit costs. For the share of a whole pair's
// matching, set them beside bench_nearest_descriptors' search of the pair.
#include <benchmark/benchmark.h>

#include <random>

#include "colmap_ext/camera/camera.h"
#include "pipelines/features/relative_pose_refinement.h"
#include "pipelines/features/two_view_verification.h"

namespace portcal {
namespace {

struct Pair {
  Camera camera = Camera::FromModelName("PINHOLE", 700, 960, 540);
  Rigid3d cam2_from_cam1{
      Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
      Eigen::Vector3d(-0.5, 0.02, 0.05)};
  FeatureKeypoints keypoints1, keypoints2;
  FeatureMatches matches;
  std::vector<Eigen::Vector2d> inliers1, inliers2;  // normalised, the true matches
};

Pair MakePair(int num_matches, double chance_fraction) {
  Pair pair;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> noise(0, 0.5);
  const auto inside = [](const Eigen::Vector2d& p) {
    return p.x() >= 0 && p.x() <= 960 && p.y() >= 0 && p.y() <= 540;
  };
  while (static_cast<int>(pair.matches.size()) < num_matches) {
    const Eigen::Vector3d x(-2 + 4 * u(rng), -1 + 2 * u(rng), 3 + 3 * u(rng));
    const auto p1 = pair.camera.ImgFromCam(x);
    const auto p2 = pair.camera.ImgFromCam(pair.cam2_from_cam1 * x);
    if (!p1 || !p2 || !inside(*p1) || !inside(*p2)) continue;
    const bool chance = u(rng) < chance_fraction;
    FeatureKeypoint k1, k2;
    k1.x = static_cast<float>(p1->x() + noise(rng));
    k1.y = static_cast<float>(p1->y() + noise(rng));
    k2.x = static_cast<float>(chance ? 960 * u(rng) : p2->x() + noise(rng));
    k2.y = static_cast<float>(chance ? 540 * u(rng) : p2->y() + noise(rng));
    const auto index = static_cast<uint32_t>(pair.keypoints1.size());
    pair.keypoints1.push_back(k1);
    pair.keypoints2.push_back(k2);
    pair.matches.push_back({index, index});
    if (chance) continue;
    const auto r1 = pair.camera.CamFromImg(Eigen::Vector2d(k1.x, k1.y));
    const auto r2 = pair.camera.CamFromImg(Eigen::Vector2d(k2.x, k2.y));
    pair.inliers1.push_back(r1->hnormalized());
    pair.inliers2.push_back(r2->hnormalized());
  }
  return pair;
}

void BM_VerifyTwoView(benchmark::State& state) {
  const Pair pair = MakePair(static_cast<int>(state.range(0)), 0.3);
  for (auto _ : state) {
    const TwoViewGeometry geometry =
        VerifyTwoView(pair.camera, pair.keypoints1, pair.camera, pair.keypoints2, pair.matches,
                      TwoViewVerificationOptions());
    benchmark::DoNotOptimize(geometry.cam2_from_cam1.translation.data());
  }
}

// From a start 1 degree off, as RANSAC's five-match pose is.
void BM_RefineRelativePose(benchmark::State& state) {
  const Pair pair = MakePair(static_cast<int>(state.range(0)), 0.3);
  const Rigid3d start(pair.cam2_from_cam1.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(
                                                         M_PI / 180, Eigen::Vector3d::UnitY())),
                      pair.cam2_from_cam1.translation.normalized());
  for (auto _ : state) {
    const auto refined = RefineRelativePose(pair.inliers1, pair.inliers2, start, 1.0 / 700);
    benchmark::DoNotOptimize(refined);
  }
  state.counters["inliers"] = static_cast<double>(pair.inliers1.size());
}

BENCHMARK(BM_VerifyTwoView)->Arg(900)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RefineRelativePose)->Arg(900)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace portcal
BENCHMARK_MAIN();
