#include "pipelines/features/image_retrieval.h"

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "colmap_ext/util/error.h"

namespace portcal {

VisualVocabulary VisualVocabulary::Train(const std::vector<UnitDescriptors>& samples, int num_words,
                                         int max_samples) {
  int64_t total = 0;
  for (const UnitDescriptors& d : samples) total += d.rows();
  if (total < num_words) {
    throw InputError("image retrieval: " + std::to_string(total) + " descriptors are too few for " +
                     std::to_string(num_words) + " visual words");
  }
  const double stride = std::max(1.0, static_cast<double>(total) / max_samples);
  cv::Mat data;
  double next = 0;
  int64_t index = 0;
  for (const UnitDescriptors& d : samples) {
    for (Eigen::Index r = 0; r < d.rows(); ++r, ++index) {
      if (index + 1e-9 < next) continue;
      next += stride;
      cv::Mat row(1, 128, CV_32F);
      for (int c = 0; c < 128; ++c) row.at<float>(0, c) = d(r, c);
      data.push_back(row);
    }
  }
  cv::theRNG().state = 0x5eed;  // k-means++ seeding: same data, same words
  cv::Mat labels, centers;
  cv::kmeans(data, num_words, labels,
             cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-4), 1,
             cv::KMEANS_PP_CENTERS, centers);
  VisualVocabulary vocabulary;
  vocabulary.words_.resize(centers.rows, 128);
  for (int r = 0; r < centers.rows; ++r) {
    for (int c = 0; c < 128; ++c) vocabulary.words_(r, c) = centers.at<float>(r, c);
  }
  return vocabulary;
}

std::vector<int> VisualVocabulary::Assign(const UnitDescriptors& descriptors) const {
  // Nearest word by Euclidean distance: argmax of d.w - |w|^2 / 2.
  const Eigen::VectorXf half_norms = 0.5f * words_.rowwise().squaredNorm();
  std::vector<int> assignment(static_cast<size_t>(descriptors.rows()));
  constexpr Eigen::Index kBlock = 2048;
  for (Eigen::Index start = 0; start < descriptors.rows(); start += kBlock) {
    const Eigen::Index rows = std::min(kBlock, descriptors.rows() - start);
    Eigen::MatrixXf scores = descriptors.middleRows(start, rows) * words_.transpose();
    scores.rowwise() -= half_norms.transpose();
    for (Eigen::Index r = 0; r < rows; ++r) {
      Eigen::Index best;
      scores.row(r).maxCoeff(&best);
      assignment[static_cast<size_t>(start + r)] = static_cast<int>(best);
    }
  }
  return assignment;
}

void ImageRetrievalIndex::Add(const std::vector<int>& words) {
  Eigen::VectorXf counts = Eigen::VectorXf::Zero(num_words_);
  for (int w : words) counts(w) += 1;
  counts_.push_back(counts);
}

void ImageRetrievalIndex::Finalize() {
  const int n = static_cast<int>(counts_.size());
  Eigen::VectorXf document_frequency = Eigen::VectorXf::Zero(num_words_);
  for (const Eigen::VectorXf& c : counts_)
    document_frequency += (c.array() > 0).cast<float>().matrix();
  const Eigen::VectorXf idf =
      (static_cast<float>(n) / document_frequency.array().max(1.0f)).log().matrix();
  histograms_.resize(num_words_, n);
  for (int i = 0; i < n; ++i) {
    const float total = std::max(1.0f, counts_[i].sum());
    Eigen::VectorXf h = (counts_[i] / total).cwiseProduct(idf);
    const float norm = h.norm();
    histograms_.col(i) = norm > 0 ? Eigen::VectorXf(h / norm) : h;
  }
}

}  // namespace portcal
