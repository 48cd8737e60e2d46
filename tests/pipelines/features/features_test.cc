// SIFT keypoints in COLMAP's pixel convention and descriptors as COLMAP
// stores them; mutual nearest-neighbour matching with the ratio test.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "colmap_ext/util/error.h"
#include "pipelines/features/descriptor_matching.h"
#include "pipelines/features/sift.h"

namespace portcal {
namespace {

// A Gaussian blob centred at `center` (COLMAP pixels).
cv::Mat Blob(const Eigen::Vector2d& center, double sigma) {
  cv::Mat image(200, 200, CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const double dx = c + 0.5 - center.x(), dy = r + 0.5 - center.y();
      image.at<uint8_t>(r, c) = cv::saturate_cast<uint8_t>(
          40 + 180 * std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma)));
    }
  }
  return image;
}

TEST(Sift, KeypointOfABlobIsAtItsCentreInColmapPixels) {
  // OpenCV 4.6 reports first-octave keypoints 0.25 px off; portcal undoes it
  // (a control without the correction would be off by ~0.25 px).
  for (const Eigen::Vector2d& center :
       {Eigen::Vector2d(100.5, 100.5), Eigen::Vector2d(100.8, 100.1)}) {
    const SiftFeatures features = ExtractSift(Blob(center, 4.0), SiftExtractionOptions());
    ASSERT_FALSE(features.keypoints.empty());
    double best = 1e9;
    for (const FeatureKeypoint& k : features.keypoints) {
      best = std::min(best, (Eigen::Vector2d(k.x, k.y) - center).norm());
    }
    EXPECT_LT(best, 0.06) << center.transpose();
  }
}

TEST(Sift, DescriptorsAreRootSiftQuantisedLikeColmap) {
  float descriptor[128];
  for (int k = 0; k < 128; ++k) descriptor[k] = static_cast<float>(k % 7);
  uint8_t out[128];
  QuantizeRootSift(descriptor, out);
  double norm = 0, l1 = 0;
  for (int k = 0; k < 128; ++k) l1 += descriptor[k];
  for (int k = 0; k < 128; ++k) {
    EXPECT_EQ(out[k], static_cast<uint8_t>(
                          std::min(255.0, std::round(512 * std::sqrt(descriptor[k] / l1)))));
    norm += (out[k] / 512.0) * (out[k] / 512.0);
  }
  EXPECT_NEAR(std::sqrt(norm), 1.0, 0.01);  // unit length before quantisation
}

TEST(DescriptorMatching, FindsMutualNearestNeighboursAndRejectsAmbiguousOnes) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 60);
  FeatureDescriptors a(50, 128), b(50, 128);
  for (int r = 0; r < 50; ++r) {
    for (int c = 0; c < 128; ++c) a(r, c) = static_cast<uint8_t>(byte(rng));
  }
  // b = a permuted, slightly perturbed; rows 0 and 1 of a made identical so
  // that their matches are ambiguous.
  a.row(1) = a.row(0);
  std::vector<int> perm(50);
  for (int i = 0; i < 50; ++i) perm[i] = (i * 17 + 5) % 50;
  for (int i = 0; i < 50; ++i) {
    for (int c = 0; c < 128; ++c)
      b(perm[i], c) = static_cast<uint8_t>(std::min(255, a(i, c) + (c % 3 == 0)));
  }
  for (const char* method : {"brute_force", "kdtree"}) {
    DescriptorMatchingOptions options;
    options.method = method;
    const FeatureMatches matches =
        MatchDescriptors(ToUnitDescriptors(a), ToUnitDescriptors(b), options);
    EXPECT_EQ(matches.size(), 48u) << method;
    for (const FeatureMatch& m : matches) {
      EXPECT_GE(m.point2D_idx1, 2u) << method;
      EXPECT_EQ(static_cast<int>(m.point2D_idx2), perm[m.point2D_idx1]) << method;
    }
  }
  DescriptorMatchingOptions bad;
  bad.method = "flann";
  EXPECT_THROW(bad.Check(), OptionError);
}

}  // namespace
}  // namespace portcal
