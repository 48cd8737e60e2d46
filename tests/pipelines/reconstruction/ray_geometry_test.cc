// Ray geometry behind a housing: triangulation of refracted rays,
// generalized absolute pose with outliers, the focal length from markers.
#include "pipelines/reconstruction/ray_geometry.h"

#include <gtest/gtest.h>

#include <random>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {
namespace {

// Rays of a camera behind a tilted flat port, for generalized pose tests.
struct PortRig {
  Camera camera = Camera::FromModelName("PINHOLE", 800, 1000, 800);
  Housing housing = Housing::FromName(
      "FLATPORT", {0.0871557, 0.0, 0.9961947, 0.03, 0.01, 1.0, 1.49, 1.334}, "test");
};

TEST(RayGeometry, TriangulatesRefractedRaysExactly) {
  const PortRig rig;
  const Eigen::Vector3d point(0.1, -0.05, 1.2);
  const Rigid3d cam1;  // identity
  const Rigid3d cam2(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
                     Eigen::Vector3d(-0.3, 0.02, 0.05));
  std::vector<Ray3d> rays;
  for (const Rigid3d& pose : {cam1, cam2}) {
    const auto pixel = ProjectPoint(rig.camera, &rig.housing, pose * point);
    ASSERT_TRUE(pixel);
    const auto ray = UnprojectPixel(rig.camera, &rig.housing, *pixel);
    ASSERT_TRUE(ray);
    rays.push_back(RayInWorld(*ray, pose));
  }
  const auto x = TriangulateRays(rays);
  ASSERT_TRUE(x);
  EXPECT_LT((*x - point).norm(), 1e-9);
  EXPECT_GT(MaxTriangulationAngle(rays, point), 0.2);
}

TEST(RayGeometry, GeneralizedAbsolutePoseRecoversThePoseBehindAPortWithOutliers) {
  const PortRig rig;
  const Rigid3d truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized())),
      Eigen::Vector3d(0.1, -0.2, 0.4));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Ray3d> rays;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 80; ++i) {
    const Eigen::Vector3d in_cam(0.4 * u(rng), 0.3 * u(rng), 1.0 + 0.3 * u(rng));
    const Eigen::Vector3d world = truth.Inverse() * in_cam;
    auto pixel = ProjectPoint(rig.camera, &rig.housing, in_cam);
    ASSERT_TRUE(pixel);
    if (i % 5 == 0) *pixel += Eigen::Vector2d(40 * u(rng), 40 * u(rng));  // 20 % outliers
    const auto ray = UnprojectPixel(rig.camera, &rig.housing, *pixel);
    ASSERT_TRUE(ray);
    rays.push_back(*ray);
    points.push_back(world);
  }
  std::vector<char> inliers;
  const auto pose =
      EstimateGeneralizedAbsolutePose(rays, points, GeneralizedAbsolutePoseOptions(), &inliers);
  ASSERT_TRUE(pose);
  // The inliers are exact, so only the solver's stop separates the pose
  // from the truth: OpenGV's nonlinear refinement stops when a step is
  // below 1e10 x machine epsilon (2.2e-6) of its parameters' norm (the
  // translation and the Cayley vector, ~0.5 here), ~1e-6. The bounds
  // allow ten such steps (1e-6 passed with gcc and failed with clang, 1.2e-6 rad).
  EXPECT_LT((pose->translation - truth.translation).norm(), 1e-5);
  EXPECT_LT(pose->rotation.angularDistance(truth.rotation), 1e-5);
  int correct = 0;
  for (int i = 0; i < 80; ++i) correct += inliers[i] == (i % 5 != 0);
  EXPECT_GE(correct, 78);
}

TEST(RayGeometry, FocalLengthFromMarkerQuads) {
  const double f = 1100, cx = 640, cy = 360;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<MarkerQuad> quads;
  for (int m = 0; m < 30; ++m) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.6 * u(rng), Eigen::Vector3d(u(rng), u(rng), 0.3).normalized())
            .toRotationMatrix();
    const Eigen::Vector3d t(0.2 * u(rng), 0.1 * u(rng), 0.8 + 0.2 * u(rng));
    MarkerQuad quad;
    const double s = 0.05;
    const Eigen::Vector3d corners[4] = {{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0}};
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d p = R * corners[c] + t;
      quad.corners[c] = Eigen::Vector2d(f * p.x() / p.z() + cx, f * p.y() / p.z() + cy);
    }
    quads.push_back(quad);
  }
  const auto estimate = FocalLengthFromMarkers(quads, cx, cy);
  ASSERT_TRUE(estimate);
  EXPECT_NEAR(*estimate, f, 0.5);  // float homographies: sub-pixel
  EXPECT_FALSE(FocalLengthFromMarkers({quads[0], quads[1]}, cx, cy));  // too few
}

}  // namespace
}  // namespace portcal
