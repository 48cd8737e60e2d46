#include "pipelines/features/descriptor_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>

#include "colmap_ext/util/error.h"

namespace portcal {

void DescriptorMatchingOptions::Check() const {
  if (!(max_ratio > 0 && max_ratio <= 1)) {
    throw OptionError("--SiftMatching.max_ratio", max_ratio, "in (0, 1]");
  }
  if (!(max_distance > 0 && max_distance <= M_PI)) {
    throw OptionError("--SiftMatching.max_distance", max_distance, "in (0, pi]");
  }
  if (max_num_matches < 1) {
    throw OptionError("--SiftMatching.max_num_matches", max_num_matches, ">= 1");
  }
  if (method != "brute_force" && method != "kdtree") {
    throw OptionError("--SiftMatching.method", method, "brute_force or kdtree");
  }
  if (kdtree_num_trees < 1) {
    throw OptionError("--SiftMatching.kdtree_num_trees", kdtree_num_trees, ">= 1");
  }
  if (kdtree_num_checks < 1) {
    throw OptionError("--SiftMatching.kdtree_num_checks", kdtree_num_checks, ">= 1");
  }
}

UnitDescriptors ToUnitDescriptors(const FeatureDescriptors& descriptors) {
  UnitDescriptors unit = descriptors.cast<float>();
  for (Eigen::Index r = 0; r < unit.rows(); ++r) {
    const float norm = unit.row(r).norm();
    if (norm > 0) unit.row(r) /= norm;
  }
  return unit;
}

namespace {

// The two nearest rows of `data` for each row of `queries`, by k-d trees.
// FLANN's L2 distances are squared; for unit vectors dot = 1 - d^2 / 2.
void NearestKdTree(const UnitDescriptors& data, const UnitDescriptors& queries,
                   const DescriptorMatchingOptions& options,
                   std::vector<NearestDescriptors>* nearest) {
  const cv::Mat data_mat(static_cast<int>(data.rows()), 128, CV_32F,
                         const_cast<float*>(data.data()));
  const cv::Mat query_mat(static_cast<int>(queries.rows()), 128, CV_32F,
                          const_cast<float*>(queries.data()));
  const int k = data.rows() > 1 ? 2 : 1;
  cv::flann::Index index(data_mat, cv::flann::KDTreeIndexParams(options.kdtree_num_trees));
  cv::Mat indices, distances;
  index.knnSearch(query_mat, indices, distances, k,
                  cv::flann::SearchParams(options.kdtree_num_checks));
  for (int q = 0; q < query_mat.rows; ++q) {
    NearestDescriptors& n = (*nearest)[static_cast<size_t>(q)];
    n.index = indices.at<int>(q, 0);
    if (n.index < 0) continue;
    n.best = 1.0f - 0.5f * distances.at<float>(q, 0);
    if (k == 2 && indices.at<int>(q, 1) >= 0) n.second = 1.0f - 0.5f * distances.at<float>(q, 1);
  }
}

}  // namespace

FeatureMatches MatchDescriptors(const UnitDescriptors& descriptors1,
                                const UnitDescriptors& descriptors2,
                                const DescriptorMatchingOptions& options) {
  const Eigen::Index n1 = descriptors1.rows(), n2 = descriptors2.rows();
  FeatureMatches matches;
  if (n1 == 0 || n2 == 0) return matches;
  std::vector<NearestDescriptors> nearest1, nearest2;
  if (options.method == "kdtree") {
    nearest1.resize(static_cast<size_t>(n1));
    nearest2.resize(static_cast<size_t>(n2));
    NearestKdTree(descriptors2, descriptors1, options, &nearest1);
    if (options.cross_check) NearestKdTree(descriptors1, descriptors2, options, &nearest2);
  } else {
    FindNearestDescriptors(descriptors1, descriptors2, &nearest1, &nearest2);
  }
  const auto angle = [](float dot) { return std::acos(std::min(1.0f, std::max(-1.0f, dot))); };
  for (Eigen::Index i = 0; i < n1; ++i) {
    const NearestDescriptors& a = nearest1[static_cast<size_t>(i)];
    if (a.index < 0) continue;
    const float best = angle(a.best);
    if (best > options.max_distance) continue;
    // With a single candidate there is no second best: the ratio test passes.
    if (n2 > 1 && best >= options.max_ratio * angle(a.second)) continue;
    if (options.cross_check) {
      // COLMAP's cross check: the reverse match passes the same tests.
      const NearestDescriptors& b = nearest2[static_cast<size_t>(a.index)];
      if (b.index != i) continue;
      if (n1 > 1 && angle(b.best) >= options.max_ratio * angle(b.second)) continue;
    }
    matches.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(a.index)});
    if (static_cast<int>(matches.size()) >= options.max_num_matches) break;
  }
  return matches;
}

}  // namespace portcal
