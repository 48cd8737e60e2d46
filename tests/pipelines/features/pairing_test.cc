// Which pairs each matcher matches, as COLMAP's matchers pair them: every
// pair once; each image with its next `overlap` images and, quadratic, the
// images 2^k ahead; the nearest positions within the distance.
#include "pipelines/features/pairing.h"

#include <gtest/gtest.h>

#include <set>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace {

std::set<std::pair<image_t, image_t>> AsSet(const ImagePairs& pairs) {
  return {pairs.begin(), pairs.end()};
}

TEST(Pairing, ExhaustiveIsEveryPairOnce) {
  const std::vector<image_t> images = {4, 7, 9, 12, 13};
  const ImagePairs pairs = ExhaustivePairs(images);
  EXPECT_EQ(pairs.size(), 10u);
  EXPECT_EQ(AsSet(pairs).size(), 10u);
  for (const auto& [a, b] : pairs) EXPECT_LT(a, b);  // in name order, never an image with itself
  EXPECT_TRUE(ExhaustivePairs({3}).empty());
}

TEST(Pairing, SequentialIsTheOverlapAndThePowersOfTwoAhead) {
  std::vector<image_t> images;
  for (image_t id = 1; id <= 40; ++id) images.push_back(id);
  SequentialPairingOptions options;
  options.overlap = 3;
  options.quadratic_overlap = false;
  const auto plain = AsSet(SequentialPairs(images, options));
  EXPECT_EQ(plain.size(), 37u * 3 + 2 + 1);  // the last images have fewer ahead
  EXPECT_TRUE(plain.count({1, 4}));
  EXPECT_FALSE(plain.count({1, 5}));

  options.quadratic_overlap = true;  // also 1, 2, 4 ahead: only 4 is new
  const auto quadratic = AsSet(SequentialPairs(images, options));
  EXPECT_TRUE(quadratic.count({1, 5}));
  EXPECT_FALSE(quadratic.count({1, 6}));
  EXPECT_FALSE(quadratic.count({1, 9}));  // 2^3 is beyond k < overlap
  EXPECT_EQ(quadratic.size(), plain.size() + 36);
}

TEST(Pairing, SpatialIsTheNearestWithinTheDistance) {
  // A line of images 1 m apart, and one far away.
  std::vector<std::pair<image_t, Eigen::Vector3d>> positions;
  for (image_t id = 1; id <= 6; ++id) positions.emplace_back(id, Eigen::Vector3d(id, 0, id * 5.0));
  positions.emplace_back(99, Eigen::Vector3d(100, 100, 0));
  SpatialPairingOptions options;
  options.max_num_neighbors = 2;
  options.max_distance_m = 1.5;
  options.ignore_z = true;                      // the z offsets are depth, not distance
  std::set<std::pair<image_t, image_t>> pairs;  // each found from both ends
  for (const auto& [a, b] : SpatialPairs(positions, options))
    pairs.emplace(std::min(a, b), std::max(a, b));
  for (const auto& [a, b] : pairs) {
    EXPECT_NE(a, 99u);
    EXPECT_NE(b, 99u);
    EXPECT_EQ(std::max(a, b) - std::min(a, b), 1u) << a << " " << b;
  }
  EXPECT_EQ(pairs.size(), 5u);
  options.ignore_z = false;  // 5 m apart in z: nothing is near
  EXPECT_TRUE(SpatialPairs(positions, options).empty());
}

TEST(Pairing, OptionsOutsideTheirRangeNameTheFlag) {
  SequentialPairingOptions sequential;
  sequential.overlap = 0;
  EXPECT_THROW(sequential.Check(), OptionError);
  SpatialPairingOptions spatial;
  spatial.max_distance_m = 0;
  try {
    spatial.Check();
    ADD_FAILURE();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--SpatialMatching.max_distance"), std::string::npos);
  }
}

}  // namespace
}  // namespace portcal
