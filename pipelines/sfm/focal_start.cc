#include "pipelines/sfm/focal_start.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"
#include "colmap_ext/util/string_utils.h"
#include "pipelines/sfm/pair_matches.h"

namespace portcal {

void FocalStartOptions::Check() const {
  if (!(min_focal_factor > 0 && min_focal_factor < max_focal_factor)) {
    throw OptionError("--Mapper.init_focal_min_factor", min_focal_factor,
                      "> 0 and < --Mapper.init_focal_max_factor");
  }
  if (!(max_focal_factor <= 100)) {
    throw OptionError("--Mapper.init_focal_max_factor", max_focal_factor, "<= 100");
  }
  if (num_steps < 5 || num_steps > 1000) {
    throw OptionError("--Mapper.init_focal_num_steps", num_steps, "5 to 1000");
  }
  if (max_num_pairs < 2) {
    throw OptionError("--Mapper.init_focal_max_num_pairs", max_num_pairs, ">= 2");
  }
  if (max_matches_per_pair < 16) {
    throw OptionError("--Mapper.init_focal_max_matches", max_matches_per_pair, ">= 16");
  }
  if (!(min_contrast >= 0)) {
    throw OptionError("--Mapper.init_focal_min_contrast", min_contrast, ">= 0");
  }
}

namespace {

constexpr double kContrastStep = 1.3;

// Mean over the pairs of how far each pair's fundamental matrix, fitted to
// the rays of focal length `focal`, is from an essential matrix.
double CostAt(const std::vector<PixelMatches>& pairs, const HousedCamera& camera, double focal) {
  Camera trial = camera.camera;
  for (const int idx : CameraModelFocalLengthIdxs(trial.model_id)) trial.params[idx] = focal;
  const Housing* housing = camera.HousingOrNull();
  double sum = 0;
  for (const PixelMatches& matches : pairs) {
    std::vector<Eigen::Vector2d> x1, x2;
    if (!NormalisedRays(matches, trial, housing, &x1, &x2)) {
      return std::numeric_limits<double>::infinity();
    }
    const Eigen::Vector3d singular =
        Eigen::JacobiSVD<Eigen::Matrix3d>(FitFundamentalRobustly(x1, x2)).singularValues();
    if (!(singular(0) > 0)) return std::numeric_limits<double>::infinity();
    sum += (singular(0) - singular(1)) / (singular(0) + singular(1));
  }
  return sum / static_cast<double>(pairs.size());
}

// The focal length of least cost on the grid, refined by a parabola in
// log f; nullopt (and why) at the range's end or where the cost is flat.
std::optional<FocalStart> Sweep(const std::vector<PixelMatches>& pairs, const HousedCamera& camera,
                                const FocalStartOptions& options, std::string* why_not) {
  const double side = static_cast<double>(std::max(camera.camera.width, camera.camera.height));
  const double log_min = std::log(options.min_focal_factor * side);
  const double log_step =
      (std::log(options.max_focal_factor * side) - log_min) / (options.num_steps - 1);
  const auto focal_at = [&](double i) { return std::exp(log_min + i * log_step); };
  std::vector<double> costs(options.num_steps);
  ParallelFor(costs.size(), 2, [&](size_t i) {
    costs[i] = CostAt(pairs, camera, focal_at(static_cast<double>(i)));
  });
  const size_t best = std::min_element(costs.begin(), costs.end()) - costs.begin();
  if (!std::isfinite(costs[best])) {
    *why_not = "no focal length in the search range turns every keypoint into a ray";
    return std::nullopt;
  }
  if (best == 0 || best + 1 == costs.size()) {
    *why_not = "the best focal length lies at the search range's end (" +
               FormatSignificant(focal_at(static_cast<double>(best)), 4) + " px)";
    return std::nullopt;
  }
  const double c0 = costs[best - 1], c1 = costs[best], c2 = costs[best + 1];
  const double curvature = c0 - 2 * c1 + c2;
  const double offset = curvature > 0 ? std::clamp(0.5 * (c0 - c2) / curvature, -1.0, 1.0) : 0.0;
  FocalStart start;
  start.focal = focal_at(static_cast<double>(best) + offset);
  start.cost = CostAt(pairs, camera, start.focal);
  if (!(start.cost <= c1)) {
    start.focal = focal_at(static_cast<double>(best));
    start.cost = c1;
  }
  const double away = std::min(CostAt(pairs, camera, start.focal / kContrastStep),
                               CostAt(pairs, camera, start.focal * kContrastStep));
  start.contrast = start.cost > 0 ? away / start.cost - 1 : std::numeric_limits<double>::infinity();
  if (!(start.contrast >= options.min_contrast)) {
    *why_not = "the views do not tell it (the cost 30 % away is only " +
               FormatSignificant(100 * start.contrast, 2) + " % above its minimum at " +
               FormatSignificant(start.focal, 4) +
               " px: moving straight ahead or turning about the optical axis, or a strong "
               "distortion not yet known?)";
    return std::nullopt;
  }
  return start;
}

}  // namespace

std::optional<FocalStart> EstimateFocalFromPairs(const SfmInputs& inputs, camera_t camera_id,
                                                 const HousedCamera& camera,
                                                 const FocalStartOptions& options,
                                                 std::string* why_not) {
  options.Check();
  const std::vector<PixelMatches> pairs =
      BestMatchedPairs(inputs, camera_id, options.max_num_pairs, options.max_matches_per_pair);
  if (pairs.size() < 2) {
    *why_not = std::to_string(pairs.size()) + " non-planar pairs with 16 matches or more";
    return std::nullopt;
  }
  std::optional<FocalStart> start = Sweep(pairs, camera, options, why_not);
  if (!start) return std::nullopt;
  start->num_pairs = static_cast<int>(pairs.size());
  for (const PixelMatches& matches : pairs) start->num_matches += static_cast<int>(matches.size());
  return start;
}

}  // namespace portcal
