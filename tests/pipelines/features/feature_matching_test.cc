// Matching's two costly parts: the brute-force search for each descriptor's
// two nearest neighbours (the AVX2 kernel must give what the portable
// product and scan give, ties included) and the geometric verification
// (true matches of a calibrated pair kept, its relative pose fitted to
// them, and chance matches of unrelated images rejected).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "colmap_ext/camera/camera.h"
#include "pipelines/features/nearest_descriptors.h"
#include "pipelines/features/relative_pose_refinement.h"
#include "pipelines/features/two_view_verification.h"

namespace portcal {
namespace {

// Unit rows drawn like COLMAP-normalised SIFT (non-negative, a few large
// bins); with `copies`, some of them copies of earlier rows so that equal
// products occur.
UnitDescriptorRows RandomDescriptors(int rows, std::mt19937* rng, bool copies = true) {
  std::uniform_int_distribution<int> byte(0, 40);
  std::uniform_int_distribution<int> spike(0, 9);
  UnitDescriptorRows d(rows, 128);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 128; ++c)
      d(r, c) = static_cast<float>(byte(*rng) + (spike(*rng) == 0 ? 120 : 0));
    d.row(r).normalize();
  }
  if (copies) {
    for (int r = 7; r < rows; r += 11) d.row(r) = d.row(r / 3);
  }
  return d;
}

// Row i of `near` in each set: the index where the best product is clear of
// the second (a near tie may fall either way by rounding), the products to
// float rounding.
void ExpectSameNearest(const std::vector<NearestDescriptors>& expected,
                       const std::vector<NearestDescriptors>& actual, const std::string& what) {
  ASSERT_EQ(expected.size(), actual.size()) << what;
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(expected[i].best, actual[i].best, 1e-5) << what << " row " << i;
    EXPECT_NEAR(expected[i].second, actual[i].second, 1e-5) << what << " row " << i;
    if (expected[i].best - expected[i].second > 1e-5) {
      EXPECT_EQ(expected[i].index, actual[i].index) << what << " row " << i;
    }
  }
}

TEST(NearestDescriptors, Avx2KernelAgreesWithThePortableProduct) {
  UnitDescriptorRows probe(1, 128);
  probe.setConstant(1.0f / std::sqrt(128.0f));
  std::vector<NearestDescriptors> n1, n2;
  if (!FindNearestDescriptorsAvx2(probe, probe, &n1, &n2))
    GTEST_SKIP() << "this CPU has no AVX2 + FMA";
  std::mt19937 rng(11);
  // Sizes on and off the kernel's tiles (3 x 4) and chunks (48 columns).
  for (const auto& [rows1, rows2] : std::vector<std::pair<int, int>>{
           {1, 1}, {2, 3}, {3, 4}, {4, 5}, {5, 47}, {7, 48}, {49, 50}, {300, 97}, {1001, 517}}) {
    const UnitDescriptorRows a = RandomDescriptors(rows1, &rng);
    const UnitDescriptorRows b = RandomDescriptors(rows2, &rng);
    std::vector<NearestDescriptors> p1, p2, v1, v2;
    FindNearestDescriptorsPortable(a, b, &p1, &p2);
    ASSERT_TRUE(FindNearestDescriptorsAvx2(a, b, &v1, &v2));
    const std::string size = std::to_string(rows1) + " x " + std::to_string(rows2);
    ExpectSameNearest(p1, v1, size + ", rows of the first");
    ExpectSameNearest(p2, v2, size + ", rows of the second");
  }
}

TEST(NearestDescriptors, EqualProductsGoToTheFirstRowInBothImplementations) {
  std::mt19937 rng(5);
  const UnitDescriptorRows a = RandomDescriptors(40, &rng, false);
  // b: each row of a twice (rows 2k and 2k + 1), then unrelated rows, so
  // row k of a has two exactly equal best products and the first must win.
  UnitDescriptorRows b(90, 128);
  for (int k = 0; k < 40; ++k) b.row(2 * k) = b.row(2 * k + 1) = a.row(k);
  b.bottomRows(10) = RandomDescriptors(10, &rng);
  std::vector<NearestDescriptors> n1, n2;
  const auto check = [&](const std::string& what) {
    for (int k = 0; k < 40; ++k) {
      EXPECT_EQ(n1[k].index, 2 * k) << what << " row " << k;
      EXPECT_EQ(n1[k].best, n1[k].second) << what << " row " << k;
    }
  };
  FindNearestDescriptorsPortable(a, b, &n1, &n2);
  check("portable");
  if (FindNearestDescriptorsAvx2(a, b, &n1, &n2)) check("AVX2");
}

// A calibrated pair over a scene 3-6 m deep, 0.5 m baseline, with 0.5 px
// noise, and matches of which `outlier_fraction` are replaced by random
// pixels (their indices recorded).
struct SyntheticPair {
  Camera camera = Camera::FromModelName("PINHOLE", 700, 960, 540);
  FeatureKeypoints keypoints1, keypoints2;
  FeatureMatches matches;
  std::vector<bool> is_outlier;
  Rigid3d cam2_from_cam1;
};

SyntheticPair MakePair(int num_points, double outlier_fraction, std::mt19937* rng) {
  SyntheticPair pair;
  pair.cam2_from_cam1 =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
              Eigen::Vector3d(-0.5, 0.02, 0.05));
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> noise(0, 0.5);
  while (static_cast<int>(pair.matches.size()) < num_points) {
    const Eigen::Vector3d x(-2 + 4 * u(*rng), -1 + 2 * u(*rng), 3 + 3 * u(*rng));
    const auto p1 = pair.camera.ImgFromCam(x);
    const auto p2 = pair.camera.ImgFromCam(pair.cam2_from_cam1 * x);
    if (!p1 || !p2 || p2->x() < 0 || p2->x() > 960 || p2->y() < 0 || p2->y() > 540) continue;
    if (p1->x() < 0 || p1->x() > 960 || p1->y() < 0 || p1->y() > 540) continue;
    const bool outlier = u(*rng) < outlier_fraction;
    FeatureKeypoint k1, k2;
    k1.x = static_cast<float>(p1->x() + noise(*rng));
    k1.y = static_cast<float>(p1->y() + noise(*rng));
    k2.x = static_cast<float>(outlier ? 960 * u(*rng) : p2->x() + noise(*rng));
    k2.y = static_cast<float>(outlier ? 540 * u(*rng) : p2->y() + noise(*rng));
    const auto index = static_cast<uint32_t>(pair.keypoints1.size());
    pair.keypoints1.push_back(k1);
    pair.keypoints2.push_back(k2);
    pair.matches.push_back({index, index});
    pair.is_outlier.push_back(outlier);
  }
  return pair;
}

TEST(TwoViewVerification, KeepsTheTrueMatchesOfACalibratedPair) {
  std::mt19937 rng(7);
  const SyntheticPair pair = MakePair(900, 0.3, &rng);
  const TwoViewGeometry geometry =
      VerifyTwoView(pair.camera, pair.keypoints1, pair.camera, pair.keypoints2, pair.matches,
                    TwoViewVerificationOptions());
  EXPECT_EQ(geometry.config, TwoViewGeometryConfig::kCalibrated);
  int true_kept = 0, false_kept = 0, num_true = 0;
  for (bool o : pair.is_outlier) num_true += !o;
  for (const FeatureMatch& m : geometry.inlier_matches) {
    (pair.is_outlier[m.point2D_idx1] ? false_kept : true_kept) += 1;
  }
  // At 0.5 px noise and a 4 px threshold every true match passes; a random
  // pixel falls within 4 px of its epipolar line with probability ~1 %.
  EXPECT_GE(true_kept, 0.99 * num_true);
  EXPECT_LE(false_kept, 0.03 * (900 - num_true));
  // The pose is fitted to the ~630 true matches: at 0.5 px their Fisher
  // information (Sampson's distance, this pair's geometry) gives standard
  // deviations of 0.062 deg for the rotation and 0.17 deg for the
  // translation's direction (the narrow field of view lets the two trade).
  // Bounds at about 3 of them; a minimal sample's pose was 1.1 deg off here.
  const double angle =
      geometry.cam2_from_cam1.rotation.angularDistance(pair.cam2_from_cam1.rotation);
  EXPECT_LT(angle, 0.2 * M_PI / 180);
  const Eigen::Vector3d t = pair.cam2_from_cam1.translation.normalized();
  EXPECT_GT(geometry.cam2_from_cam1.translation.normalized().dot(t), std::cos(0.5 * M_PI / 180));
  std::cout << "relative pose: rotation " << angle * 180 / M_PI << " deg, translation "
            << std::acos(std::min(1.0, geometry.cam2_from_cam1.translation.normalized().dot(t))) *
                   180 / M_PI
            << " deg off\n";
}

// Normalised coordinates of a pair's matches: points 3-6 m in front of
// camera 1, with `noise` (normalised units) on each coordinate.
void NormalisedMatches(const Rigid3d& cam2_from_cam1, int num_points, double noise,
                       std::mt19937* rng, std::vector<Eigen::Vector2d>* points1,
                       std::vector<Eigen::Vector2d>* points2) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> n(0, noise);
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d x(1.5 * u(*rng), 1.0 * u(*rng), 4.5 + 1.5 * u(*rng));
    const Eigen::Vector3d y = cam2_from_cam1 * x;
    points1->emplace_back(x.x() / x.z() + n(*rng), x.y() / x.z() + n(*rng));
    points2->emplace_back(y.x() / y.z() + n(*rng), y.y() / y.z() + n(*rng));
  }
}

TEST(RelativePoseRefinement, ConvergesToTheExactPoseFromADegreeOff) {
  const Rigid3d truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
      Eigen::Vector3d(-0.5, 0.02, 0.05).normalized());
  std::mt19937 rng(3);
  std::vector<Eigen::Vector2d> points1, points2;
  NormalisedMatches(truth, 100, 0.0, &rng, &points1, &points2);
  const Rigid3d start(
      truth.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 180, Eigen::Vector3d::UnitY())),
      (truth.translation + Eigen::Vector3d(0, 0.05, 0.05)).normalized());
  const auto refined = RefineRelativePose(points1, points2, start, 0.0);
  ASSERT_TRUE(refined);
  // Exact matches: only the solver's stop separates it from the truth.
  EXPECT_LT(refined->rotation.angularDistance(truth.rotation), 1e-8);
  EXPECT_NEAR(refined->translation.norm(), 1.0, 1e-12);
  EXPECT_GT(refined->translation.dot(truth.translation), 1 - 1e-12);
}

TEST(RelativePoseRefinement, FewerThanFiveMatchesOrNoBaselineAreNotRefined) {
  const Rigid3d truth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  std::mt19937 rng(5);
  std::vector<Eigen::Vector2d> points1, points2;
  NormalisedMatches(truth, 4, 0.0, &rng, &points1, &points2);
  EXPECT_FALSE(RefineRelativePose(points1, points2, truth, 0.0));
  NormalisedMatches(truth, 20, 0.0, &rng, &points1, &points2);
  EXPECT_TRUE(RefineRelativePose(points1, points2, truth, 0.0));
  EXPECT_FALSE(RefineRelativePose(points1, points2, Rigid3d(),
                                  0.0));  // zero translation: no direction to refine
  points2.pop_back();
  EXPECT_FALSE(RefineRelativePose(points1, points2, truth, 0.0));
}

TEST(TwoViewVerification, RejectsTheChanceMatchesOfUnrelatedImages) {
  std::mt19937 rng(9);
  for (int trial = 0; trial < 5; ++trial) {
    const SyntheticPair pair = MakePair(70, 1.0, &rng);
    const TwoViewGeometry geometry =
        VerifyTwoView(pair.camera, pair.keypoints1, pair.camera, pair.keypoints2, pair.matches,
                      TwoViewVerificationOptions());
    EXPECT_EQ(geometry.config, TwoViewGeometryConfig::kDegenerate) << "trial " << trial;
    EXPECT_TRUE(geometry.inlier_matches.empty()) << "trial " << trial;
  }
}

}  // namespace
}  // namespace portcal
