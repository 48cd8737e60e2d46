// The seabed's ray search: its hits lie on the relief, and a search started
// where a neighbouring ray hit (as the renderer starts each ray of a pixel
// row) finds the hit that the search from the mean plane finds.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "pipelines/synthetic/scene.h"

namespace portcal {
namespace {

class UniformTexture : public FaceTexture {
 public:
  bool Gray(double, double, float* gray) const override {
    *gray = 128;
    return true;
  }
  Eigen::Vector4d Extent() const override { return Eigen::Vector4d(-1e3, -1e3, 1e3, 1e3); }
};

// Newton's error after its last step s is about |f''| / (2 |f'|) s^2: with
// s < 1e-6 m, |f''| <= sum a k^2 = 19 / m for this relief and |f'| > 0.5
// for rays within 25 deg of nadir, under 2e-11 m; 1e-10 m leaves a margin.
constexpr double kOnReliefTolerance = 1e-10;

double OffRelief(const SeabedObject& seabed, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& dir, const Hit& hit) {
  const Eigen::Vector3d p = origin + hit.t * dir;
  return p.z() - seabed.Height(p.x(), p.y());
}

TEST(SeabedObject, ANeighboursStartFindsTheSameHitOnTheRelief) {
  // The surveys' relief: 0.15 m standard deviation over a 2 m wavelength.
  const SeabedObject seabed(std::make_shared<UniformTexture>(), 0.15, 2.0, 7);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> position(-20, 20), azimuth(0, 2 * M_PI),
      tilt(0, 25 * M_PI / 180);
  for (int i = 0; i < 2000; ++i) {
    const double a = tilt(rng), b = azimuth(rng);
    const Eigen::Vector3d dir =
        Eigen::Vector3d(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), -std::cos(a))
            .normalized();
    const Eigen::Vector3d origin(position(rng), position(rng), 2.0);
    Hit from_plane;
    ASSERT_TRUE(seabed.Intersect(origin, dir, 1e300, &from_plane)) << "ray " << i;
    EXPECT_NEAR(OffRelief(seabed, origin, dir, from_plane), 0, kOnReliefTolerance) << "ray " << i;

    // The next sample of a pixel row: a ray 1 mm over, started at this hit.
    const Eigen::Vector3d beside = origin + Eigen::Vector3d(1e-3, 0, 0);
    Hit near, reference;
    ASSERT_TRUE(seabed.IntersectNear(beside, dir, 1e300, from_plane.t, &near)) << "ray " << i;
    ASSERT_TRUE(seabed.Intersect(beside, dir, 1e300, &reference)) << "ray " << i;
    EXPECT_NEAR(OffRelief(seabed, beside, dir, near), 0, kOnReliefTolerance) << "ray " << i;
    EXPECT_NEAR(near.t, reference.t, 2 * kOnReliefTolerance / std::abs(dir.z())) << "ray " << i;

    // No neighbour yet (0): the search starts from the mean plane.
    Hit unhinted;
    ASSERT_TRUE(seabed.IntersectNear(origin, dir, 1e300, 0.0, &unhinted));
    EXPECT_EQ(unhinted.t, from_plane.t);
  }
}

TEST(SeabedObject, RaysThatDoNotLookDownOrEndBeforeTheSeabedMissIt) {
  const SeabedObject seabed(std::make_shared<UniformTexture>(), 0.15, 2.0, 7);
  Hit hit;
  EXPECT_FALSE(
      seabed.IntersectNear(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, 1), 1e300, 2.0, &hit));
  EXPECT_FALSE(
      seabed.IntersectNear(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, -1), 1.0, 2.0, &hit));
  EXPECT_TRUE(
      seabed.IntersectNear(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0, 0, -1), 3.0, 2.0, &hit));
}

}  // namespace
}  // namespace portcal
