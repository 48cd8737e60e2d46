#include "pipelines/sfm/radial_start.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "colmap_ext/geometry/hartley_normalization.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/parallel.h"
#include "colmap_ext/util/string_utils.h"

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

using Matches = std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>;  // pixels in a, in b

double SampsonSquared(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2) {
  const Eigen::Vector3d p1 = x1.homogeneous(), p2 = x2.homogeneous();
  const Eigen::Vector3d Fp1 = F * p1, Ftp2 = F.transpose() * p2;
  const double e = p2.dot(Fp1);
  const double denominator = Fp1.head<2>().squaredNorm() + Ftp2.head<2>().squaredNorm();
  return denominator > 0 ? e * e / denominator : std::numeric_limits<double>::infinity();
}

// The eight-point fundamental matrix x2' F x1 = 0, each row weighted (the
// reweighting by the Sampson denominator makes the algebraic fit
// approximate the geometric one), rank 2 enforced.
Eigen::Matrix3d FitFundamental(const std::vector<Eigen::Vector2d>& x1,
                               const std::vector<Eigen::Vector2d>& x2,
                               const std::vector<double>& weights) {
  const Eigen::Matrix3d T1 = HartleyNormalization(x1), T2 = HartleyNormalization(x2);
  Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < x1.size(); ++i) {
    if (weights[i] <= 0) continue;
    const Eigen::Vector3d a = T1 * x1[i].homogeneous(), b = T2 * x2[i].homogeneous();
    Eigen::Matrix<double, 9, 1> row;
    row << b.x() * a.x(), b.x() * a.y(), b.x(), b.y() * a.x(), b.y() * a.y(), b.y(), a.x(), a.y(),
        1;
    AtA += weights[i] * row * row.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eigen(AtA);
  const Eigen::Matrix<double, 9, 1> f = eigen.eigenvectors().col(0);
  Eigen::Matrix3d F;
  F << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = svd.singularValues();
  s(2) = 0;
  F = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  return T2.transpose() * F * T1;
}

// Sum of the smallest 80 % of the squared Sampson residuals (normalised
// coordinates) of one pair's rays, after a fit that drops what lies beyond
// three times the median: the verified inliers still hold a few wrong
// matches, and they must not choose the distortion.
std::pair<double, int> PairResidual(const std::vector<Eigen::Vector2d>& x1,
                                    const std::vector<Eigen::Vector2d>& x2) {
  std::vector<double> weights(x1.size(), 1.0), errors(x1.size());
  Eigen::Matrix3d F = FitFundamental(x1, x2, weights);
  for (int pass = 0; pass < 3; ++pass) {
    for (size_t i = 0; i < x1.size(); ++i) errors[i] = SampsonSquared(F, x1[i], x2[i]);
    std::vector<double> sorted = errors;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double cut = 9.0 * sorted[sorted.size() / 2];
    for (size_t i = 0; i < x1.size(); ++i) {
      const Eigen::Vector3d Fp1 = F * x1[i].homogeneous(),
                            Ftp2 = F.transpose() * x2[i].homogeneous();
      const double denominator = Fp1.head<2>().squaredNorm() + Ftp2.head<2>().squaredNorm();
      weights[i] = errors[i] <= cut && denominator > 0 ? 1.0 / denominator : 0.0;
    }
    F = FitFundamental(x1, x2, weights);
  }
  for (size_t i = 0; i < x1.size(); ++i) errors[i] = SampsonSquared(F, x1[i], x2[i]);
  std::sort(errors.begin(), errors.end());
  const size_t kept = std::max<size_t>(8, errors.size() * 8 / 10);
  double sum = 0;
  for (size_t i = 0; i < kept && i < errors.size(); ++i) sum += errors[i];
  return {sum, static_cast<int>(std::min(kept, errors.size()))};
}

// The best-matched non-planar pairs of the camera, their matched pixels.
std::vector<Matches> CollectPairs(const SfmInputs& inputs, camera_t camera_id,
                                  const RadialStartOptions& options) {
  std::vector<std::pair<int, image_pair_t>> ranked;
  for (const auto& [pair_id, count] : inputs.pair_inliers) {
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    if (inputs.planar_pairs.count(pair_id) || inputs.images.at(a).camera_id != camera_id ||
        inputs.images.at(b).camera_id != camera_id) {
      continue;
    }
    ranked.emplace_back(count, pair_id);
  }
  std::sort(ranked.rbegin(), ranked.rend());
  std::vector<Matches> pairs;
  for (const auto& [count, pair_id] : ranked) {
    if (static_cast<int>(pairs.size()) >= options.max_num_pairs) break;
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    const SfmImage& image_a = inputs.images.at(a);
    const SfmImage& image_b = inputs.images.at(b);
    Matches matches;
    for (point2D_t k = 0; k < image_a.correspondences.size(); ++k) {
      for (const Correspondence& c : image_a.correspondences[k]) {
        if (c.image_id == b)
          matches.emplace_back(image_a.keypoints[k], image_b.keypoints[c.point2D_idx]);
      }
    }
    if (matches.size() < 16) continue;
    // An even subsample keeps the spread of the matches over the image.
    const size_t step =
        (matches.size() + options.max_matches_per_pair - 1) / options.max_matches_per_pair;
    Matches kept;
    for (size_t i = 0; i < matches.size(); i += step) kept.push_back(matches[i]);
    pairs.push_back(std::move(kept));
  }
  return pairs;
}

// Mean squared residual over all pairs, in pixels squared, and its count,
// with the radial term k.
std::pair<double, int> ResidualAt(const std::vector<Matches>& pairs, const HousedCamera& camera,
                                  int idx, double k) {
  Camera trial = camera.camera;
  trial.params[idx] = k;
  const Housing* housing = camera.HousingOrNull();
  double sum = 0;
  int count = 0;
  for (const Matches& matches : pairs) {
    std::vector<Eigen::Vector2d> x1, x2;
    for (const auto& [pa, pb] : matches) {
      const auto ra = UnprojectPixel(trial, housing, pa);
      const auto rb = UnprojectPixel(trial, housing, pb);
      if (!ra || !rb || ra->direction.z() < 1e-3 || rb->direction.z() < 1e-3) continue;
      x1.push_back(ra->direction.hnormalized());
      x2.push_back(rb->direction.hnormalized());
    }
    // A candidate that leaves keypoints without a ray (a distortion that
    // cannot be inverted that far out) is no candidate: the residuals of the
    // rest would look better for having fewer points.
    if (x1.size() < 16 || x1.size() < matches.size() * 95 / 100) {
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
std::pair<double, double> BestRadialTerm(const std::vector<Matches>& pairs,
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
  const std::vector<Matches> pairs = CollectPairs(inputs, camera_id, options);
  if (pairs.size() < 2) return std::nullopt;
  int num_matches = 0;
  for (const Matches& matches : pairs) num_matches += static_cast<int>(matches.size());
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
