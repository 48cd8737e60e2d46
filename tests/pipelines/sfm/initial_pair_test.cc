// Which pairs the incremental mapper tries first: most inlier matches,
// homographies last, and behind a housing with the markers as the scale
// source the pairs that see a marker in common before the rest (half the
// trials at most), so that the model grows at the markers' scale from its
// first adjustment on (docs/scale.md).
#include "pipelines/sfm/initial_pair.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <vector>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {
namespace {

MarkerDetection Marker(int id) {
  MarkerDetection marker;
  marker.dictionary = "DICT_4X4_50";
  marker.marker_id = id;
  return marker;
}

// Images 1..6 of one camera; images 1 and 2 see marker 7, image 3 sees
// marker 7 of another dictionary and image 4 marker 8. The pairs' inlier
// counts rank them (5,6) > (1,3) > (3,4) > (1,2) > (2,5) by matches alone;
// (5,6) is a homography.
SfmInputs SixImages() {
  SfmInputs inputs;
  for (image_t id = 1; id <= 6; ++id) {
    inputs.images[id].image_id = id;
    inputs.images[id].camera_id = 1;
  }
  inputs.images[1].markers = {Marker(7)};
  inputs.images[2].markers = {Marker(3), Marker(7)};
  inputs.images[3].markers = {Marker(7)};
  inputs.images[3].markers[0].dictionary = "DICT_6X6_250";
  inputs.images[4].markers = {Marker(8)};
  inputs.pair_inliers = {{ImagePairToPairId(5, 6), 900}, {ImagePairToPairId(1, 3), 800},
                         {ImagePairToPairId(3, 4), 700}, {ImagePairToPairId(1, 2), 600},
                         {ImagePairToPairId(2, 5), 500}, {ImagePairToPairId(2, 4), 10}};
  inputs.planar_pairs = {ImagePairToPairId(5, 6)};
  return inputs;
}

std::map<camera_t, HousedCamera> OneCamera(bool housed) {
  HousedCamera camera;
  camera.camera = Camera::FromModelName("RADIAL", 700, 960, 540);
  if (housed)
    camera.housing = Housing::FromName("FLATPORT", {0, 0, 1, 0.01, 0.01, 1, 1.473, 1.334}, "test");
  return {{1, camera}};
}

IncrementalMapperOptions WithMarkers(double side_length_m) {
  IncrementalMapperOptions options;
  options.init_min_num_inliers = 100;
  options.marker_scale.side_length_m = side_length_m;
  return options;
}

std::vector<image_pair_t> Pairs(const std::vector<std::pair<image_t, image_t>>& pairs) {
  std::vector<image_pair_t> ids;
  for (const auto& [a, b] : pairs) ids.push_back(ImagePairToPairId(a, b));
  return ids;
}

TEST(RankInitialPairs, MostMatchesFirstHomographiesLastAndTooFewMatchesNever) {
  const SfmInputs inputs = SixImages();
  const auto ranked = RankInitialPairs(inputs, OneCamera(true), WithMarkers(0), {}, {});
  EXPECT_EQ(ranked, Pairs({{1, 3}, {3, 4}, {1, 2}, {2, 5}, {5, 6}}));
  // In air the markers' scale is a gauge the refinement sets: no reorder.
  EXPECT_EQ(RankInitialPairs(inputs, OneCamera(false), WithMarkers(0.15), {}, {}), ranked);
}

TEST(RankInitialPairs, BehindAHousingPairsSeeingOneMarkerComeFirst) {
  const SfmInputs inputs = SixImages();
  // Only (1,2) sees one marker from both images: (1,3) shares its id but
  // not its dictionary, (3,4) no marker at all.
  EXPECT_EQ(RankInitialPairs(inputs, OneCamera(true), WithMarkers(0.15), {}, {}),
            Pairs({{1, 2}, {1, 3}, {3, 4}, {2, 5}, {5, 6}}));
  // Pairs with used images or already tried drop out as before.
  EXPECT_EQ(
      RankInitialPairs(inputs, OneCamera(true), WithMarkers(0.15), {}, {ImagePairToPairId(1, 2)}),
      Pairs({{1, 3}, {3, 4}, {2, 5}, {5, 6}}));
  EXPECT_EQ(RankInitialPairs(inputs, OneCamera(true), WithMarkers(0.15), {3}, {}),
            Pairs({{1, 2}, {2, 5}, {5, 6}}));
}

TEST(RankInitialPairs, MarkerPairsTakeAtMostHalfTheTrials) {
  SfmInputs inputs = SixImages();
  for (image_t id : {3, 4, 5}) inputs.images[id].markers = {Marker(7)};
  IncrementalMapperOptions options = WithMarkers(0.15);
  options.init_max_num_trials = 4;
  // Marker pairs (1,3) (3,4) (1,2) (2,5), not the homography (5,6): the two
  // best go first, the other two keep their places by their matches.
  EXPECT_EQ(RankInitialPairs(inputs, OneCamera(true), options, {}, {}),
            Pairs({{1, 3}, {3, 4}, {1, 2}, {2, 5}, {5, 6}}));
  inputs.pair_inliers[ImagePairToPairId(3, 4)] = 100;
  inputs.pair_inliers[ImagePairToPairId(1, 2)] = 150;
  inputs.pair_inliers[ImagePairToPairId(1, 6)] = 950;  // image 6 sees no marker
  EXPECT_EQ(RankInitialPairs(inputs, OneCamera(true), options, {}, {}),
            Pairs({{1, 3}, {2, 5}, {1, 6}, {1, 2}, {3, 4}, {5, 6}}));
}

}  // namespace
}  // namespace portcal
