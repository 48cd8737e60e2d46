#include "pipelines/sfm/pair_matches.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>

#include "colmap_ext/geometry/hartley_normalization.h"

namespace portcal {
namespace {

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

}  // namespace

double SampsonSquared(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1,
                      const Eigen::Vector2d& x2) {
  const Eigen::Vector3d p1 = x1.homogeneous(), p2 = x2.homogeneous();
  const Eigen::Vector3d Fp1 = F * p1, Ftp2 = F.transpose() * p2;
  const double e = p2.dot(Fp1);
  const double denominator = Fp1.head<2>().squaredNorm() + Ftp2.head<2>().squaredNorm();
  return denominator > 0 ? e * e / denominator : std::numeric_limits<double>::infinity();
}

Eigen::Matrix3d FitFundamentalRobustly(const std::vector<Eigen::Vector2d>& x1,
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
  return F;
}

bool NormalisedRays(const PixelMatches& matches, const Camera& camera, const Housing* housing,
                    std::vector<Eigen::Vector2d>* x1, std::vector<Eigen::Vector2d>* x2) {
  x1->clear();
  x2->clear();
  for (const auto& [pa, pb] : matches) {
    const auto ra = UnprojectPixel(camera, housing, pa);
    const auto rb = UnprojectPixel(camera, housing, pb);
    if (!ra || !rb || ra->direction.z() < 1e-3 || rb->direction.z() < 1e-3) continue;
    x1->push_back(ra->direction.hnormalized());
    x2->push_back(rb->direction.hnormalized());
  }
  return x1->size() >= 16 && x1->size() >= matches.size() * 95 / 100;
}

std::vector<PixelMatches> BestMatchedPairs(const SfmInputs& inputs, camera_t camera_id,
                                           int max_num_pairs, int max_matches_per_pair) {
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
  std::vector<PixelMatches> pairs;
  for (const auto& [count, pair_id] : ranked) {
    if (static_cast<int>(pairs.size()) >= max_num_pairs) break;
    image_t a, b;
    PairIdToImagePair(pair_id, &a, &b);
    const SfmImage& image_a = inputs.images.at(a);
    const SfmImage& image_b = inputs.images.at(b);
    PixelMatches matches;
    for (point2D_t k = 0; k < image_a.correspondences.size(); ++k) {
      for (const Correspondence& c : image_a.correspondences[k]) {
        if (c.image_id == b)
          matches.emplace_back(image_a.keypoints[k], image_b.keypoints[c.point2D_idx]);
      }
    }
    if (matches.size() < 16) continue;
    // An even subsample keeps the spread of the matches over the image.
    const size_t step = (matches.size() + max_matches_per_pair - 1) / max_matches_per_pair;
    PixelMatches kept;
    for (size_t i = 0; i < matches.size(); i += step) kept.push_back(matches[i]);
    pairs.push_back(std::move(kept));
  }
  return pairs;
}

}  // namespace portcal
