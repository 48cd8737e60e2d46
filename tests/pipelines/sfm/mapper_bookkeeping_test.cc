// The mapper's bookkeeping: the count of each image's keypoints that would
// link to a point of the model, kept up to date as observations come and
// go, must equal a walk over the correspondences, and the points a set of
// images sees (a local adjustment's) a walk over every point's track; and
// the measure of how far a refinement of the intrinsics and housing moved
// the image, by which the mapper stops refining them.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "colmap_ext/camera/camera.h"
#include "colmap_ext/util/error.h"
#include "pipelines/reconstruction/reconstruction.h"
#include "pipelines/sfm/camera_change.h"
#include "pipelines/sfm/incremental_mapper.h"

namespace portcal {
namespace {

// What NextImages counted before the count was kept up to date.
int VisiblePointsByWalk(const Reconstruction& r, image_t image_id) {
  int visible = 0;
  for (const auto& correspondences : r.inputs().images.at(image_id).correspondences) {
    for (const Correspondence& c : correspondences) {
      if (r.PointOf(c.image_id, c.point2D_idx) != kInvalidPoint3DId) {
        ++visible;
        break;
      }
    }
  }
  return visible;
}

// What the local adjustment and filter took before PointsSeenBy.
std::vector<point3D_t> PointsSeenByWalk(const Reconstruction& r, const std::set<image_t>& images) {
  std::vector<point3D_t> ids;
  for (const auto& [id, point] : r.points()) {
    bool seen = false;
    for (const TrackElement& e : point.track) seen |= images.count(e.image_id) > 0;
    if (seen) ids.push_back(id);
  }
  return ids;
}

TEST(Reconstruction, VisiblePointCountsFollowEveryObservationChange) {
  // Six images of 40 keypoints and 300 random matches between them: a
  // keypoint has 2.5 correspondences on average, so it can see a point
  // through several, and lose one of them without losing sight.
  std::mt19937 rng(7);
  SfmInputs inputs;
  inputs.cameras[1].camera = Camera::FromModelName("SIMPLE_PINHOLE", 500, 640, 480);
  inputs.cameras[1].camera.camera_id = 1;
  constexpr int kImages = 6, kKeypoints = 40;
  for (image_t id = 1; id <= kImages; ++id) {
    SfmImage& image = inputs.images[id];
    image.image_id = id;
    image.camera_id = 1;
    for (int k = 0; k < kKeypoints; ++k) image.keypoints.emplace_back(10 + k, 20 + k);
    image.correspondences.resize(kKeypoints);
  }
  std::uniform_int_distribution<int> image_of(1, kImages), keypoint_of(0, kKeypoints - 1);
  for (int m = 0; m < 300; ++m) {
    const image_t a = image_of(rng), b = image_of(rng);
    if (a == b) continue;
    const point2D_t ka = keypoint_of(rng), kb = keypoint_of(rng);
    inputs.images.at(a).correspondences[ka].push_back({b, kb});
    inputs.images.at(b).correspondences[kb].push_back({a, ka});
  }

  Reconstruction r(&inputs, inputs.cameras);
  size_t points_seen = 0;
  const auto expect_counts = [&](const std::string& after) {
    for (image_t id = 1; id <= kImages; ++id) {
      ASSERT_EQ(r.NumVisiblePoints(id), VisiblePointsByWalk(r, id))
          << "image " << id << " after " << after;
    }
    // The points of each pair of images and of a single image (an image not
    // registered sees none).
    for (image_t a = 1; a <= kImages; ++a) {
      for (image_t b = a; b <= kImages; ++b) {
        const std::set<image_t> images = {a, b};
        const std::vector<point3D_t> seen = r.PointsSeenBy(images);
        ASSERT_EQ(seen, PointsSeenByWalk(r, images)) << a << ", " << b << " after " << after;
        points_seen += seen.size();
      }
    }
  };
  expect_counts("construction");
  for (image_t id = 1; id <= 4; ++id) r.Register(id, Rigid3d());

  // Random points and observations added, deleted, points deleted, images
  // deregistered and registered again.
  int operations = 0, nonzero = 0;
  for (int step = 0; step < 2000; ++step) {
    const int what = std::uniform_int_distribution<int>(0, 9)(rng);
    const image_t id = image_of(rng);
    const point2D_t k = keypoint_of(rng);
    if (what <= 3 && r.IsRegistered(id) && r.PointOf(id, k) == kInvalidPoint3DId) {
      std::vector<TrackElement> track{{id, k}};
      const image_t other = image_of(rng);
      const point2D_t other_k = keypoint_of(rng);
      if (other != id && r.IsRegistered(other) && r.PointOf(other, other_k) == kInvalidPoint3DId) {
        track.push_back({other, other_k});
        r.AddPoint(Eigen::Vector3d::Zero(), track);
        ++operations;
      }
    } else if (what <= 5 && r.IsRegistered(id) && r.PointOf(id, k) == kInvalidPoint3DId &&
               !r.points().empty()) {
      auto it = r.points().begin();
      std::advance(it, std::uniform_int_distribution<size_t>(0, r.points().size() - 1)(rng));
      r.AddObservation(it->first, {id, k});
      ++operations;
    } else if (what <= 7 && r.IsRegistered(id)) {
      r.DeleteObservation(id, k);  // a no-op where the keypoint has no point
      ++operations;
    } else if (what == 8 && !r.points().empty()) {
      r.DeletePoint(r.points().begin()->first);
      ++operations;
    } else if (what == 9) {
      if (r.IsRegistered(id)) {
        r.Deregister(id);
      } else {
        r.Register(id, Rigid3d());
      }
      ++operations;
    }
    expect_counts("operation " + std::to_string(operations));
    for (image_t i = 1; i <= kImages; ++i) nonzero += r.NumVisiblePoints(i) > 0;
  }
  EXPECT_GT(operations, 500);
  EXPECT_GT(nonzero, 2000);  // the counts were exercised, not zero throughout
  EXPECT_GT(points_seen, 10000u);
}

HousedCamera Pinhole(double f) {
  HousedCamera camera;
  camera.camera = Camera::FromModelName("PINHOLE", f, 960, 540);
  camera.camera.params = {f, f, 480, 270};
  return camera;
}

TEST(CameraChange, FocalLengthScalesTheImageAboutThePrincipalPointAtAnyDepth) {
  // Pinhole: a point seen at pixel p is seen at c + (1 + e)(p - c) with the
  // focal length (1 + e) f, whatever its depth; the grid's farthest pixels
  // from c are the corner pixels' centres, 479.5 and 269.5 px away.
  const double corner = std::hypot(479.5, 269.5);
  for (const double depth : {0.5, 2.0, 30.0}) {
    EXPECT_LT(MaxImageShiftPx(Pinhole(700), Pinhole(700), depth), 1e-9);  // the round trip
    EXPECT_NEAR(MaxImageShiftPx(Pinhole(700), Pinhole(700 * 1.001), depth), 0.001 * corner, 1e-9)
        << depth;
  }
}

TEST(CameraChange, AFlatPortsDistanceMovesTheImageLessWithDepth) {
  // Moving the port moves the virtual centres of the rays: a parallax that
  // falls off as 1 / depth.
  const auto behind_port = [](double distance) {
    HousedCamera camera = Pinhole(700);
    camera.housing = Housing::FromName(
        "FLATPORT", {0.05, 0.0, std::sqrt(1 - 0.0025), distance, 0.01, 1, 1.473, 1.334}, "test");
    return camera;
  };
  const double near = MaxImageShiftPx(behind_port(0.020), behind_port(0.021), 1.0);
  const double far = MaxImageShiftPx(behind_port(0.020), behind_port(0.021), 4.0);
  EXPECT_LT(MaxImageShiftPx(behind_port(0.020), behind_port(0.020), 1.0), 1e-9);
  EXPECT_GT(near, 0.01);
  EXPECT_NEAR(far / near, 0.25, 0.01);
}

TEST(IncrementalMapperOptions, BadSettlingOptionsAreNamed) {
  IncrementalMapperOptions options;
  options.ba_calibration_settled_px = 0;
  EXPECT_NO_THROW(options.Check());
  options.ba_calibration_settled_px = -0.1;
  try {
    options.Check();
    ADD_FAILURE() << "accepted -0.1";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--Mapper.ba_calibration_settled_px"), std::string::npos)
        << e.what();
  }
  options.ba_calibration_settled_px = 0.25;
  options.ba_calibration_settled_min_images = 1;
  try {
    options.Check();
    ADD_FAILURE() << "accepted a minimum of 1 image";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--Mapper.ba_calibration_settled_min_images"),
              std::string::npos)
        << e.what();
  }
}

TEST(IncrementalMapperOptions, GlobalFunctionToleranceIsAFractionAndNamedWhenBad) {
  IncrementalMapperOptions options;
  EXPECT_NO_THROW(options.Check());
  for (const double bad : {0.0, -1e-5, 1.0, std::nan("")}) {
    options.ba_global_function_tolerance = bad;
    try {
      options.Check();
      ADD_FAILURE() << "accepted " << bad;
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("--Mapper.ba_global_function_tolerance"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(IncrementalMapperOptions, GlobalUnsettledWeightsAreAFractionAndNamedWhenBad) {
  IncrementalMapperOptions options;
  options.ba_global_max_unsettled_weights = 0;  // the cost change alone
  EXPECT_NO_THROW(options.Check());
  for (const double bad : {-0.01, 1.0, std::nan("")}) {
    options.ba_global_max_unsettled_weights = bad;
    try {
      options.Check();
      ADD_FAILURE() << "accepted " << bad;
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("--Mapper.ba_global_max_unsettled_weights"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(IncrementalMapperOptions, NegativeRestartsAreNamed) {
  IncrementalMapperOptions options;
  options.init_max_restarts = 0;
  EXPECT_NO_THROW(options.Check());
  options.init_max_restarts = -1;
  try {
    options.Check();
    ADD_FAILURE() << "accepted -1";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--Mapper.init_max_restarts"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace portcal
