// ChooseCalibrationSubset on the pair graph of a lawnmower survey: 4 lines
// of 25 images, each image verified with the next 5 along the path (the
// turns included) with fewer inliers the farther apart, as a sequential
// matcher's overlap 5 gives.
#include "pipelines/sfm/calibration_subset.h"

#include <gtest/gtest.h>

#include "colmap_ext/util/error.h"
#include "database/feature_types.h"

namespace portcal {
namespace {

constexpr int kNumImages = 100;

std::vector<image_t> Ordered() {
  std::vector<image_t> ordered;
  for (int i = 1; i <= kNumImages; ++i) ordered.push_back(static_cast<image_t>(i));
  return ordered;
}

// Inliers 500, 420, ..., 180 for 1 to 5 images apart; none across `gap`
// (pairs of an image before it with one at or after it) when > 0.
std::map<image_pair_t, int> Pairs(int gap = 0) {
  std::map<image_pair_t, int> pairs;
  for (int i = 1; i <= kNumImages; ++i) {
    for (int d = 1; d <= 5 && i + d <= kNumImages; ++d) {
      if (gap > 0 && i < gap && i + d >= gap) continue;
      pairs[ImagePairToPairId(static_cast<image_t>(i), static_cast<image_t>(i + d))] =
          500 - 80 * (d - 1);
    }
  }
  return pairs;
}

void ExpectChained(const CalibrationSubset& subset, const std::map<image_pair_t, int>& pairs,
                   int min_inliers) {
  for (size_t k = 1; k < subset.images.size(); ++k) {
    const auto it = pairs.find(ImagePairToPairId(subset.images[k - 1], subset.images[k]));
    ASSERT_NE(it, pairs.end()) << subset.images[k - 1] << " - " << subset.images[k];
    EXPECT_GE(it->second, min_inliers);
  }
}

TEST(CalibrationSubset, SpreadOverEveryLineAndChained) {
  CalibrationSubsetOptions options;
  options.num_images = 25;
  const CalibrationSubset subset = ChooseCalibrationSubset(Ordered(), Pairs(), options);
  EXPECT_EQ(subset.num_breaks, 0);
  EXPECT_GE(subset.images.size(), 25u);
  EXPECT_LE(subset.images.size(), 30u);
  EXPECT_EQ(subset.images.front(), 1u);
  EXPECT_EQ(subset.images.back(), static_cast<image_t>(kNumImages));
  ExpectChained(subset, Pairs(), options.min_num_inliers);
  int per_line[4] = {0, 0, 0, 0};
  for (image_t id : subset.images) ++per_line[(id - 1) / 25];
  for (int line = 0; line < 4; ++line) EXPECT_GE(per_line[line], 5) << "line " << line;
}

TEST(CalibrationSubset, PairsThatReachLessThanTheStrideKeepMoreImages) {
  CalibrationSubsetOptions options;
  options.num_images = 10;        // a stride of 11 images
  options.min_num_inliers = 300;  // links reach 3 images
  const CalibrationSubset subset = ChooseCalibrationSubset(Ordered(), Pairs(), options);
  EXPECT_EQ(subset.num_breaks, 0);
  EXPECT_GE(subset.images.size(), 33u);  // 99 images of path in steps of at most 3
  ExpectChained(subset, Pairs(), options.min_num_inliers);
}

TEST(CalibrationSubset, AGapInThePairsIsABreak) {
  CalibrationSubsetOptions options;
  options.num_images = 25;
  const std::map<image_pair_t, int> pairs = Pairs(/*gap=*/50);
  const CalibrationSubset subset = ChooseCalibrationSubset(Ordered(), pairs, options);
  EXPECT_EQ(subset.num_breaks, 1);
  EXPECT_EQ(subset.images.back(), static_cast<image_t>(kNumImages));
  int unlinked = 0;
  for (size_t k = 1; k < subset.images.size(); ++k) {
    unlinked += !pairs.count(ImagePairToPairId(subset.images[k - 1], subset.images[k]));
  }
  EXPECT_EQ(unlinked, 1);
}

TEST(CalibrationSubset, OptionsAreChecked) {
  CalibrationSubsetOptions options;
  options.num_images = 1;
  EXPECT_THROW(ChooseCalibrationSubset(Ordered(), Pairs(), options), OptionError);
  options.num_images = 10;
  options.min_num_inliers = 0;
  EXPECT_THROW(ChooseCalibrationSubset(Ordered(), Pairs(), options), OptionError);
}

}  // namespace
}  // namespace portcal
