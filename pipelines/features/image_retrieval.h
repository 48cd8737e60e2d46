// Image retrieval for loop closure: a bag of visual words (Sivic and
// Zisserman 2003) with tf-idf weighting. The vocabulary is k-means over a
// sample of the database's own descriptors; an image is the L2-normalised
// tf-idf histogram of its descriptors' nearest words, and two images are as
// similar as the dot product of their histograms.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pipelines/features/descriptor_matching.h"

namespace portcal {

class VisualVocabulary {
 public:
  // k-means (k-means++ seeds, fixed seed) on up to `max_samples`
  // descriptors drawn evenly from `samples`.
  static VisualVocabulary Train(const std::vector<UnitDescriptors>& samples, int num_words,
                                int max_samples = 100000);
  int NumWords() const { return static_cast<int>(words_.rows()); }
  // Word index of every descriptor.
  std::vector<int> Assign(const UnitDescriptors& descriptors) const;

 private:
  UnitDescriptors words_;
};

class ImageRetrievalIndex {
 public:
  explicit ImageRetrievalIndex(int num_words) : num_words_(num_words) {}
  // Adds an image's word counts; call Finalize() before querying.
  void Add(const std::vector<int>& words);
  void Finalize();
  size_t NumImages() const { return counts_.size(); }
  // Indices (in Add order) of the `k` most similar images to image `query`,
  // most similar first, excluding those `exclude` says true for.
  template <typename Exclude>
  std::vector<int> Query(int query, int k, Exclude exclude) const;

 private:
  int num_words_;
  std::vector<Eigen::VectorXf> counts_;
  Eigen::MatrixXf histograms_;  // one normalised tf-idf column per image
};

template <typename Exclude>
std::vector<int> ImageRetrievalIndex::Query(int query, int k, Exclude exclude) const {
  const Eigen::VectorXf scores = histograms_.transpose() * histograms_.col(query);
  std::vector<int> candidates;
  for (int i = 0; i < scores.size(); ++i) {
    if (i != query && !exclude(i)) candidates.push_back(i);
  }
  const size_t keep = std::min<size_t>(candidates.size(), static_cast<size_t>(std::max(0, k)));
  std::partial_sort(candidates.begin(), candidates.begin() + keep, candidates.end(),
                    [&](int a, int b) { return scores(a) > scores(b); });
  candidates.resize(keep);
  return candidates;
}

}  // namespace portcal
