// The markers' corners across a series of global adjustments: the model
// scaled to their known side first; then a corner an adjustment placed
// keeps its place at the next one while its observations agree with it, and
// a fresh triangulation (which fits each corner to its rays alone, not to
// the side lengths) takes over only for corners seen for the first time or
// no longer agreeing. Four views of one 15 cm marker behind a flat port, the
// corners' pixels with 0.3 px of noise.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/housing/housing.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/global_adjustment.h"

namespace portcal {
namespace {

constexpr double kSide = 0.15;
constexpr double kMaxErrorPx = 4.0;

struct MarkerScene {
  SfmInputs inputs;
  std::map<image_t, Rigid3d> poses;
  std::array<Eigen::Vector3d, 4> corners;  // the truth, OpenCV's order
};

// A marker on the plane z = 2 m, seen from four camera centres 30 cm apart.
MarkerScene MakeScene(int marker_id) {
  MarkerScene scene;
  HousedCamera& camera = scene.inputs.cameras[1];
  camera.camera = Camera::FromModelName("PINHOLE", 700, 960, 540);
  camera.camera.camera_id = 1;
  camera.housing = Housing::FromName("FLATPORT", {0, 0, 1, 0.01, 0.010, 1, 1.473, 1.334}, "test");
  scene.corners = {Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(kSide, 0, 2),
                   Eigen::Vector3d(kSide, kSide, 2), Eigen::Vector3d(0, kSide, 2)};
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.3);
  const std::array<Eigen::Vector3d, 4> centres = {
      Eigen::Vector3d(-0.15, -0.15, 0), Eigen::Vector3d(0.3, -0.1, 0), Eigen::Vector3d(0.2, 0.3, 0),
      Eigen::Vector3d(-0.1, 0.25, 0)};
  for (image_t id = 1; id <= 4; ++id) {
    Rigid3d cam_from_world;
    cam_from_world.translation = -centres[id - 1];
    scene.poses[id] = cam_from_world;
    SfmImage& image = scene.inputs.images[id];
    image.image_id = id;
    image.camera_id = 1;
    MarkerDetection detection;
    detection.marker_id = marker_id;
    for (int c = 0; c < 4; ++c) {
      const auto pixel = camera.Project(cam_from_world * scene.corners[c]);
      EXPECT_TRUE(pixel.has_value());
      detection.corners[c] = *pixel + Eigen::Vector2d(noise(rng), noise(rng));
    }
    image.markers.push_back(detection);
  }
  return scene;
}

Reconstruction Register(const MarkerScene& scene) {
  Reconstruction r(&scene.inputs, scene.inputs.cameras);
  for (const auto& [id, pose] : scene.poses) r.Register(id, pose);
  return r;
}

TEST(MarkerCorners, AnAdjustedCornerKeepsItsPlaceWhileItsObservationsAgree) {
  const MarkerScene scene = MakeScene(7);
  const Reconstruction r = Register(scene);
  const std::vector<MarkerCorner> fresh = TriangulateMarkerCorners(r, kMaxErrorPx);
  ASSERT_EQ(fresh.size(), 4u);
  // The noise moves a freshly triangulated corner by far more than the side
  // lengths' sigma (0.1 mm): that is what made the held solve start high.
  double largest_move = 0;
  for (const MarkerCorner& corner : fresh) {
    largest_move = std::max(largest_move, (corner.xyz - scene.corners[corner.corner]).norm());
  }
  EXPECT_GT(largest_move, 1e-4);

  // An adjustment placed the corners (here: at the truth, within the 0.3 px
  // of every observation); the update keeps them there, observations and all.
  std::vector<MarkerCorner> adjusted = fresh;
  for (MarkerCorner& corner : adjusted) corner.xyz = scene.corners[corner.corner];
  const std::vector<MarkerCorner> kept = UpdateMarkerCorners(r, kMaxErrorPx, adjusted);
  ASSERT_EQ(kept.size(), 4u);
  for (size_t k = 0; k < kept.size(); ++k) {
    EXPECT_EQ(kept[k].xyz, scene.corners[kept[k].corner]) << "corner " << kept[k].corner;
    EXPECT_EQ(kept[k].observations.size(), fresh[k].observations.size());
  }

  // Without earlier corners it is the fresh triangulation.
  const std::vector<MarkerCorner> first = UpdateMarkerCorners(r, kMaxErrorPx, {});
  ASSERT_EQ(first.size(), 4u);
  for (size_t k = 0; k < first.size(); ++k) EXPECT_EQ(first[k].xyz, fresh[k].xyz);
}

TEST(MarkerCorners, ACornerNoLongerAgreeingOrNewIsTriangulatedAfresh) {
  const MarkerScene scene = MakeScene(7);
  const Reconstruction r = Register(scene);
  const std::vector<MarkerCorner> fresh = TriangulateMarkerCorners(r, kMaxErrorPx);
  ASSERT_EQ(fresh.size(), 4u);
  std::vector<MarkerCorner> adjusted = fresh;
  for (MarkerCorner& corner : adjusted) corner.xyz = scene.corners[corner.corner];
  // Corner 1 moved 5 cm off its rays (tens of pixels); corner 3 was never
  // placed; corners of another marker with the same corner numbers do not
  // stand in for this one's.
  adjusted[1].xyz += Eigen::Vector3d(0.05, 0, 0);
  adjusted.erase(adjusted.begin() + 3);
  MarkerCorner other = fresh[2];
  other.marker_id = 8;
  other.xyz = Eigen::Vector3d(5, 5, 5);
  adjusted.push_back(other);
  const std::vector<MarkerCorner> updated = UpdateMarkerCorners(r, kMaxErrorPx, adjusted);
  ASSERT_EQ(updated.size(), 4u);
  EXPECT_EQ(updated[0].xyz, scene.corners[0]);
  EXPECT_EQ(updated[1].xyz, fresh[1].xyz);
  EXPECT_EQ(updated[2].xyz, scene.corners[2]);
  EXPECT_EQ(updated[3].xyz, fresh[3].xyz);
}

// A model grown at another scale than the markers' (the mapper's, under a
// housing guess, came out 2.7-3.7 times theirs): scaled back so that the
// triangulated sides have their known length, to the noise (0.3 px on a
// ~40 px side: about 1 %), the cameras' centres with it.
TEST(MarkerCorners, ScaleToMarkersBringsTheModelToTheMarkersSideLength) {
  const MarkerScene scene = MakeScene(7);
  Reconstruction r = Register(scene);
  constexpr double kGrownAt = 3.0;
  for (auto& [id, pose] : r.mutable_poses()) pose.translation *= kGrownAt;
  const auto scale = ScaleToMarkers(&r, kMaxErrorPx, kSide);
  ASSERT_TRUE(scale.has_value());
  EXPECT_NEAR(*scale * kGrownAt, 1.0, 0.02);
  for (const auto& [id, pose] : r.poses()) {
    EXPECT_LT((pose.translation - scene.poses.at(id).translation).norm(), 0.02 * 0.5)
        << "image " << id;
  }
  const std::vector<MarkerCorner> corners = TriangulateMarkerCorners(r, kMaxErrorPx);
  ASSERT_EQ(corners.size(), 4u);
  EXPECT_NEAR((corners[0].xyz - corners[1].xyz).norm(), kSide, 0.02 * kSide);
  // Once at the markers' scale it stays there, to what refraction changes:
  // the port's offsets are metres too, so scaling the world is not quite a
  // similarity of the refracted rays (2.5e-5 here; the bound allows 4 times
  // that).
  EXPECT_NEAR(ScaleToMarkers(&r, kMaxErrorPx, kSide).value_or(0), 1.0, 1e-4);
}

// Scaled down, a point near the lenses may come to lie inside a port (the
// mapper met this with a port self-calibrated far out): its observations
// cannot be projected any more, and an adjustment could not start from
// them, so the rescale deletes them. Here a point 4.5 cm in front of image
// 1 and of an image 5 mm beside it, in the model grown 3 times: 1.5 cm once
// scaled back, inside the port's glass (outer surface at 2 cm).
TEST(MarkerCorners, ScaleToMarkersDeletesTheObservationsItLeavesUnprojectable) {
  MarkerScene scene = MakeScene(7);
  constexpr double kGrownAt = 3.0;
  Rigid3d beside = scene.poses.at(1);
  beside.translation.x() -= 0.005;
  scene.poses[5] = beside;
  scene.inputs.images[5].image_id = 5;
  scene.inputs.images[5].camera_id = 1;
  const Eigen::Vector3d point =
      -kGrownAt * scene.poses.at(1).translation + Eigen::Vector3d(0, 0, 0.045);
  for (image_t id : {1, 5}) {
    Rigid3d grown = scene.poses.at(id);
    grown.translation *= kGrownAt;
    const auto pixel = scene.inputs.cameras.at(1).Project(grown * point);
    ASSERT_TRUE(pixel.has_value()) << "image " << id;
    scene.inputs.images.at(id).keypoints.push_back(*pixel);
    scene.inputs.images.at(id).correspondences.resize(1);  // one per keypoint (none matched here)
  }
  Reconstruction r = Register(scene);
  for (auto& [id, pose] : r.mutable_poses()) pose.translation *= kGrownAt;
  const point3D_t id = r.AddPoint(point, {{1, 0}, {5, 0}});
  ASSERT_LT(r.ReprojectionError(1, 0, point), 1e-6);
  ASSERT_LT(r.ReprojectionError(5, 0, point), 1e-6);
  const auto scale = ScaleToMarkers(&r, kMaxErrorPx, kSide);
  ASSERT_TRUE(scale.has_value());
  ASSERT_LT(*scale * 0.045, 0.02);
  EXPECT_EQ(r.PointOf(1, 0), kInvalidPoint3DId);
  EXPECT_EQ(r.PointOf(5, 0), kInvalidPoint3DId);
  EXPECT_EQ(r.points().count(id), 0u);
}

TEST(MarkerCorners, ScaleToMarkersLeavesAModelWithoutTwoViewsOfAMarker) {
  MarkerScene scene = MakeScene(7);
  for (image_t id = 2; id <= 4; ++id) scene.inputs.images.at(id).markers.clear();
  Reconstruction r = Register(scene);
  const std::map<image_t, Rigid3d> before = r.poses();
  EXPECT_FALSE(ScaleToMarkers(&r, kMaxErrorPx, kSide).has_value());
  for (const auto& [id, pose] : r.poses()) EXPECT_EQ(pose.translation, before.at(id).translation);
}

// The ratio itself, on corners placed by hand: a marker measured as a
// rectangle 0.10 by 0.20 (sides 0.10, 0.20, 0.10, 0.20; diagonals 0.2236).
// Sides alone: known over measured is 1.5 or 0.75, the median (the upper of
// the four) 1.5. With the diagonals too, whose ratio is 0.9487 each, the
// median of six (the fourth smallest) is 0.9487. A missing corner leaves its
// sides and diagonal out; with no pair, there is no ratio.
TEST(MarkerCorners, MarkerScaleRatioIsTheMedianOverSidesAndOptionallyDiagonals) {
  std::vector<MarkerCorner> corners(4);
  const std::array<Eigen::Vector3d, 4> xyz = {Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0.1, 0, 2),
                                              Eigen::Vector3d(0.1, 0.2, 2),
                                              Eigen::Vector3d(0, 0.2, 2)};
  for (int c = 0; c < 4; ++c) {
    corners[c].marker_id = 3;
    corners[c].corner = c;
    corners[c].xyz = xyz[c];
  }
  const double diagonal_ratio = kSide * std::sqrt(2.0) / std::hypot(0.1, 0.2);
  EXPECT_NEAR(MarkerScaleRatio(corners, kSide, false).value_or(0), 1.5, 1e-12);
  EXPECT_NEAR(MarkerScaleRatio(corners, kSide, true).value_or(0), diagonal_ratio, 1e-12);
  // Without corner 2: sides 0-1 (1.5) and 3-0 (0.75), median 1.5; with the
  // diagonal 1-3 (0.9487) the median of three is 0.9487.
  corners.erase(corners.begin() + 2);
  EXPECT_NEAR(MarkerScaleRatio(corners, kSide, false).value_or(0), 1.5, 1e-12);
  EXPECT_NEAR(MarkerScaleRatio(corners, kSide, true).value_or(0), diagonal_ratio, 1e-12);
  corners.resize(1);
  EXPECT_FALSE(MarkerScaleRatio(corners, kSide, true).has_value());
}

// The mapper's step before a global adjustment: behind a housing the model
// is scaled to the markers and the corners follow; in air, where the scale
// is a gauge, it is left as it is (docs/scale.md).
TEST(MarkerCorners, PrepareMarkerCornersScalesOnlyBehindAHousing) {
  for (const bool housed : {true, false}) {
    MarkerScene scene = MakeScene(7);
    if (!housed) scene.inputs.cameras.at(1).housing.reset();
    Reconstruction r = Register(scene);
    for (auto& [id, pose] : r.mutable_poses()) pose.translation *= 3.0;
    std::vector<MarkerCorner> corners;
    const double scale = PrepareMarkerCorners(&r, kMaxErrorPx, kSide, &corners);
    ASSERT_EQ(corners.size(), 4u) << (housed ? "housed" : "in air");
    const double side = (corners[0].xyz - corners[1].xyz).norm();
    if (housed) {
      EXPECT_NEAR(scale * 3.0, 1.0, 0.02);
      EXPECT_NEAR(side, kSide, 0.02 * kSide);
    } else {
      EXPECT_EQ(scale, 1.0);
      EXPECT_NEAR(side, 3.0 * kSide, 0.06 * kSide);
    }
  }
}

}  // namespace
}  // namespace portcal
