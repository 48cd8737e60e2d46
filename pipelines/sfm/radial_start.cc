#include "pipelines/sfm/radial_start.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/sfm/pair_matches.h"

namespace portcal {

void RadialStartOptions::Check() const {
  if (!(min_k < max_k)) throw OptionError("--Mapper.init_radial_min_k", min_k, "< max_k");
  if (num_steps < 3) throw OptionError("--Mapper.init_radial_num_steps", num_steps, ">= 3");
  if (max_num_pairs < 2) {
    throw OptionError("--Mapper.init_radial_max_num_pairs", max_num_pairs, ">= 2");
  }
  if (max_matches_per_pair < 16) {
    throw OptionError("--Mapper.init_radial_max_matches", max_matches_per_pair, ">= 16");
  }
}

int FirstRadialParamIdx(const Camera& camera) {
  const std::vector<std::string> names = SplitTokens(camera.ParamsInfo(), ", ");
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == "k1" || names[i] == "k") return static_cast<int>(i);
  }
  return -1;
}

namespace {

// Sum of the smallest 80 % of the squared Sampson residuals (normalised
// coordinates) of one pair's rays, after a robust fit: wrong matches must
// not choose the distortion.
std::pair<double, int> PairResidual(const std::vector<Eigen::Vector2d>& x1,
                                    const std::vector<Eigen::Vector2d>& x2) {
  const Eigen::Matrix3d F = FitFundamentalRobustly(x1, x2);
  std::vector<double> errors(x1.size());
  for (size_t i = 0; i < x1.size(); ++i) errors[i] = SampsonSquared(F, x1[i], x2[i]);
  std::sort(errors.begin(), errors.end());
  const size_t kept = std::max<size_t>(8, errors.size() * 8 / 10);
  double sum = 0;
  for (size_t i = 0; i < kept && i < errors.size(); ++i) sum += errors[i];
  return {sum, static_cast<int>(std::min(kept, errors.size()))};
}

// Mean squared residual over all pairs, in pixels squared, and its count,
// with the radial term k.
std::pair<double, int> ResidualAt(const std::vector<PixelMatches>& pairs,
                                  const HousedCamera& camera, int idx, double k) {
  Camera trial = camera.camera;
  trial.params[idx] = k;
  const Housing* housing = camera.HousingOrNull();
  double sum = 0;
  int count = 0;
  for (const PixelMatches& matches : pairs) {
    // A distortion that cannot be inverted that far out leaves keypoints
    // without a ray: no candidate.
    std::vector<Eigen::Vector2d> x1, x2;
    if (!NormalisedRays(matches, trial, housing, &x1, &x2)) {
      return {std::numeric_limits<double>::infinity(), 0};
    }
    const auto [pair_sum, pair_count] = PairResidual(x1, x2);
    sum += pair_sum;
    count += pair_count;
  }
  // Sampson's distance in normalised coordinates times the focal length:
  // pixels.
  const double focal = trial.MeanFocalLength();
  return {count > 0 ? focal * focal * sum / count : std::numeric_limits<double>::infinity(), count};
}

// The parabola's vertex through three equally spaced samples, as an offset
// from the middle one in units of the spacing (0 where it has no minimum).
double ParabolaVertex(double c0, double c1, double c2) {
  const double curvature = c0 - 2 * c1 + c2;
  return std::isfinite(curvature) && curvature > 0
             ? std::clamp(0.5 * (c0 - c2) / curvature, -1.0, 1.0)
             : 0.0;
}

// The best k and its mean squared residual: the grid's minimum, then the
// parabola's vertex if that is lower still.
std::pair<double, double> BestRadialTerm(const std::vector<PixelMatches>& pairs,
                                         const HousedCamera& camera, int idx,
                                         const RadialStartOptions& options) {
  const double step = (options.max_k - options.min_k) / (options.num_steps - 1);
  std::vector<double> costs(options.num_steps);
  ParallelFor(costs.size(), 2, [&](size_t i) {
    costs[i] = ResidualAt(pairs, camera, idx, options.min_k + i * step).first;
  });
  const size_t best = std::min_element(costs.begin(), costs.end()) - costs.begin();
  double k = options.min_k + best * step;
  if (best > 0 && best + 1 < costs.size())
    k += step * ParabolaVertex(costs[best - 1], costs[best], costs[best + 1]);
  const double cost = ResidualAt(pairs, camera, idx, k).first;
  return cost <= costs[best] ? std::make_pair(k, cost)
                             : std::make_pair(options.min_k + best * step, costs[best]);
}

}  // namespace

std::optional<RadialStart> EstimateFirstRadialTerm(const SfmInputs& inputs, camera_t camera_id,
                                                   const HousedCamera& camera,
                                                   const RadialStartOptions& options) {
  options.Check();
  const int idx = FirstRadialParamIdx(camera.camera);
  if (idx < 0) return std::nullopt;
  const std::vector<PixelMatches> pairs =
      BestMatchedPairs(inputs, camera_id, options.max_num_pairs, options.max_matches_per_pair);
  if (pairs.size() < 2) return std::nullopt;
  int num_matches = 0;
  for (const PixelMatches& matches : pairs) num_matches += static_cast<int>(matches.size());
  RadialStart start;
  double cost;
  std::tie(start.k, cost) = BestRadialTerm(pairs, camera, idx, options);
  if (!std::isfinite(cost)) return std::nullopt;
  start.residual_px = std::sqrt(cost);
  start.residual_at_start_px =
      std::sqrt(ResidualAt(pairs, camera, idx, camera.camera.params[idx]).first);
  start.num_pairs = static_cast<int>(pairs.size());
  start.num_matches = num_matches;
  return start;
}

}  // namespace portcal
