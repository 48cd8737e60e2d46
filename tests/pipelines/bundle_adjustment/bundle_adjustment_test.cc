// The bundle adjustment's cost blocks and its covariance: the housing
// block against the full cost, the marginal and clustered covariances
// against the full one, unobservable directions named.
#include "pipelines/bundle_adjustment/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <random>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/calibration_covariance.h"

namespace portcal {
namespace {

// The housing-only width (intrinsics captured) is the full error with the
// intrinsics held: same residuals, same derivatives by pose, point and
// housing, for a flat and a dome port.
TEST(BundleCosts, HousingBlockCostEqualsTheFullCostWithIntrinsicsHeld) {
  const std::vector<double> intrinsics = {700, 484, 266, -0.05, 0.01};
  const std::vector<std::pair<int, std::vector<double>>> housings = {
      {0, {0.0523, 0.02, std::sqrt(1 - 0.0523 * 0.0523 - 0.0004), 0.02, 0.01, 1, 1.473, 1.334}},
      {1, {0.004, -0.003, 0.006, 0.05, 0.006, 1, 1.473, 1.334}}};
  for (const auto& [housing_id, housing] : housings) {
    ObservationModel model;
    model.camera_model_id = CameraModelNameToId("RADIAL");
    model.intrinsics = intrinsics;
    model.housing_model_id = housing_id;
    model.housing = housing;
    const Eigen::Vector2d observed(610.2, 180.7);
    std::unique_ptr<ceres::CostFunction> narrow(
        CreateReprojectionCost(model, CostBlocks::kPosePointHousing, observed, 0.5));
    std::unique_ptr<ceres::CostFunction> full(
        CreateReprojectionCost(model, CostBlocks::kAll, observed, 0.5));
    ASSERT_EQ(narrow->parameter_block_sizes(), (std::vector<int32_t>{7, 3, 8}));
    ASSERT_EQ(full->parameter_block_sizes(), (std::vector<int32_t>{7, 3, 5, 8}));
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, -1, 0.2).normalized()));
    double pose[7] = {rotation.x(), rotation.y(), rotation.z(), rotation.w(), 0.1, -0.05, 0.3};
    double point[3] = {0.3, -0.2, 1.4};
    double housing_params[8];
    std::copy(housing.begin(), housing.end(), housing_params);
    std::vector<double> camera = intrinsics;
    double r_narrow[2], r_full[2];
    double j_narrow[3][2 * 8], j_full[4][2 * 8];
    double* narrow_jacobians[3] = {j_narrow[0], j_narrow[1], j_narrow[2]};
    double* full_jacobians[4] = {j_full[0], j_full[1], j_full[2], j_full[3]};
    const double* narrow_blocks[3] = {pose, point, housing_params};
    const double* full_blocks[4] = {pose, point, camera.data(), housing_params};
    ASSERT_TRUE(narrow->Evaluate(narrow_blocks, r_narrow, narrow_jacobians)) << housing_id;
    ASSERT_TRUE(full->Evaluate(full_blocks, r_full, full_jacobians)) << housing_id;
    // The point is seen: the residual is not zero (a zero would hide a
    // cost that returns without computing).
    EXPECT_GT(std::hypot(r_full[0], r_full[1]), 1.0) << housing_id;
    for (int k = 0; k < 2; ++k) EXPECT_DOUBLE_EQ(r_narrow[k], r_full[k]) << housing_id;
    const int sizes[3] = {7, 3, 8};
    const int full_index[3] = {0, 1, 3};
    for (int b = 0; b < 3; ++b) {
      for (int k = 0; k < 2 * sizes[b]; ++k) {
        EXPECT_NEAR(narrow_jacobians[b][k], full_jacobians[full_index[b]][k],
                    1e-9 * (1 + std::abs(full_jacobians[full_index[b]][k])))
            << housing_id << " block " << b << " entry " << k;
      }
    }
  }
}

// y = a x + b fitted to points, a and b each a 1-block, points marginalised:
// the marginal std devs must equal those of ceres::Covariance on the full
// problem.
struct LineResidual {
  LineResidual(double x, double y) : x_(x), y_(y) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* p, T* r) const {
    r[0] = a[0] * T(x_) + b[0] + p[0] - T(y_);
    r[1] = p[0] * T(0.5) + p[1] - p[2];
    r[2] = p[1] - T(0.1 * x_);
    r[3] = p[2] - T(0.2);
    return true;
  }
  double x_, y_;
};

TEST(CalibrationCovariance, MarginalMatchesTheFullCovariance) {
  double a = 1, b = 0;
  std::vector<std::array<double, 3>> p(20, {0, 0, 0});
  ceres::Problem problem;
  for (int i = 0; i < 20; ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LineResidual, 4, 1, 1, 3>(
                                 new LineResidual(i * 0.1, 2 * i * 0.1 + 0.3 + 0.01 * (i % 3))),
                             nullptr, &a, &b, p[i].data());
  }
  ceres::Solver::Options options;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  std::vector<double*> points;
  for (auto& q : p) points.push_back(q.data());
  ceres::Covariance::Options covariance_options;
  ceres::Covariance covariance(covariance_options);
  ASSERT_TRUE(covariance.Compute({{&a, &a}, {&b, &b}, {&a, &b}}, &problem));
  double va, vb, vab;
  covariance.GetCovarianceBlock(&a, &a, &va);
  covariance.GetCovarianceBlock(&b, &b, &vb);
  covariance.GetCovarianceBlock(&a, &b, &vab);
  // The dense decomposition (2 parameters <= 1200) and the sparse one.
  for (const int max_dense_size : {1200, 0}) {
    SCOPED_TRACE(max_dense_size == 0 ? "sparse" : "dense");
    const MarginalCovariance marginal = ComputeMarginalCovariance(
        &problem, points, {&a, &b}, {&a, &b}, 1.0,
        [](const double*, int) { return std::string("?"); }, nullptr, max_dense_size);
    EXPECT_NEAR(marginal.StdDevs(&a)[0], std::sqrt(va), 1e-9);
    EXPECT_NEAR(marginal.StdDevs(&b)[0], std::sqrt(vb), 1e-9);
    // A line's slope and intercept, both fitted from x >= 0: negatively
    // correlated.
    EXPECT_LT(vab, 0);
    EXPECT_NEAR(marginal.Correlation(&a, 0, &b, 0), vab / std::sqrt(va * vb), 1e-9);
    EXPECT_NEAR(marginal.Correlation(&b, 0, &a, 0), marginal.Correlation(&a, 0, &b, 0), 1e-12);
  }
}

// Points seen in three frames, y = R(q) p + t, frame 0 held: the frames'
// rotations on Ceres' quaternion manifold, a translation with one
// coordinate held by a subset manifold, several blocks in each residual
// in either order of the reduced system's columns. The marginal
// covariance, assembled point by point from the residual blocks' own
// Jacobians and the manifolds' plus Jacobians, must equal ceres::Covariance
// on the full problem, in ambient coordinates.
struct FramedPoint {
  explicit FramedPoint(const Eigen::Vector3d& y) : y_(y) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* r) const {
    const Eigen::Quaternion<T> rotation(q[3], q[0], q[1], q[2]);  // Eigen's x, y, z, w storage
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(r);
    residual = rotation * Eigen::Map<const Eigen::Matrix<T, 3, 1>>(p) +
               Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t) - y_.cast<T>();
    return true;
  }
  Eigen::Vector3d y_;
};

TEST(CalibrationCovariance, ManifoldBlocksMatchTheFullCovariance) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::array<Eigen::Quaterniond, 3> rotations = {
      Eigen::Quaterniond::Identity(),
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized())),
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.5, Eigen::Vector3d(0, 1, 1).normalized()))};
  const std::array<Eigen::Vector3d, 3> translations = {
      Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0.5), Eigen::Vector3d(-0.5, 1, 0)};
  std::array<Eigen::Vector4d, 3> q;  // x, y, z, w
  std::array<Eigen::Vector3d, 3> t;
  for (int k = 0; k < 3; ++k) {
    q[k] = rotations[k].coeffs();
    t[k] = translations[k] + Eigen::Vector3d(0.05, -0.02, 0.03) * k;  // a start off the truth
  }
  std::vector<Eigen::Vector3d> p(15);
  ceres::Problem problem;
  for (size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d truth(std::cos(i * 0.7) * 2, std::sin(i * 1.3), 3 + 0.2 * i);
    p[i] = truth;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d error(noise(random), noise(random), noise(random));
      const Eigen::Vector3d y = rotations[k] * truth + translations[k] + error;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FramedPoint, 3, 4, 3, 3>(new FramedPoint(y)), nullptr,
          q[k].data(), t[k].data(), p[i].data());
    }
  }
  for (int k = 0; k < 3; ++k) problem.SetManifold(q[k].data(), new ceres::EigenQuaternionManifold);
  problem.SetManifold(t[2].data(), new ceres::SubsetManifold(3, {2}));
  problem.SetParameterBlockConstant(q[0].data());
  problem.SetParameterBlockConstant(t[0].data());
  ceres::Solver::Options options;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();

  // The reduced system's columns in an order unlike the residuals'.
  const std::vector<const double*> wanted = {t[1].data(), q[2].data(), q[1].data(), t[2].data()};
  std::vector<double*> others;
  for (const double* block : wanted) others.push_back(const_cast<double*>(block));
  std::vector<double*> points;
  for (Eigen::Vector3d& point : p) points.push_back(point.data());
  ceres::Covariance::Options covariance_options;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const double* a : wanted) {
    for (const double* b : wanted) pairs.emplace_back(a, b);
  }
  ASSERT_TRUE(covariance.Compute(pairs, &problem));
  for (const auto& [max_dense_size, threads] :
       {std::pair(1200, 1), std::pair(0, 1), std::pair(1200, 2)}) {
    SCOPED_TRACE(std::string(max_dense_size == 0 ? "sparse" : "dense") + ", threads " +
                 std::to_string(threads));
    const MarginalCovariance marginal = ComputeMarginalCovariance(
        &problem, points, others, wanted, 1.0, [](const double*, int) { return std::string("?"); },
        nullptr, max_dense_size, threads);
    for (const double* a : wanted) {
      for (const double* b : wanted) {
        const int na = problem.ParameterBlockSize(a), nb = problem.ParameterBlockSize(b);
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> expected(na, nb);
        covariance.GetCovarianceBlock(a, b, expected.data());
        const Eigen::MatrixXd got =
            marginal.covariance.block(marginal.offset.at(a), marginal.offset.at(b), na, nb);
        EXPECT_LT((got - expected).norm(), 1e-8 * expected.norm() + 1e-15) << "expected\n"
                                                                           << expected << "\ngot\n"
                                                                           << got;
      }
    }
    // The held coordinate has no variance.
    EXPECT_EQ(marginal.StdDevs(t[2].data())[2], 0.0);
    EXPECT_GT(marginal.StdDevs(t[2].data())[0], 0.0);
  }
}

// Only a + b is seen: the reduced system is singular, and both
// decompositions say so, naming a parameter of the unobservable direction,
// instead of returning an enormous or NaN standard deviation.
struct SumResidual {
  explicit SumResidual(double y) : y_(y) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* p, T* r) const {
    r[0] = a[0] + b[0] + p[0] - T(y_);
    r[1] = p[0] - T(0.1 * y_);
    return true;
  }
  double y_;
};

TEST(CalibrationCovariance, UnobservableDirectionIsNamedByBothDecompositions) {
  double a = 1, b = 0;
  std::vector<std::array<double, 3>> p(10, {0, 0, 0});
  ceres::Problem problem;
  std::vector<double*> points;
  for (int i = 0; i < 10; ++i) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<SumResidual, 2, 1, 1, 3>(new SumResidual(i)), nullptr, &a,
        &b, p[i].data());
    points.push_back(p[i].data());
  }
  const auto describe = [&](const double* block, int) {
    return std::string(block == &a ? "block a" : "block b");
  };
  for (const int max_dense_size : {1200, 0}) {
    SCOPED_TRACE(max_dense_size == 0 ? "sparse" : "dense");
    try {
      ComputeMarginalCovariance(&problem, points, {&a, &b}, {&a, &b}, 1.0, describe, nullptr,
                                max_dense_size);
      ADD_FAILURE() << "a singular reduced system gave a covariance";
    } catch (const NumericalError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("do not determine block"), std::string::npos) << message;
      EXPECT_NE(message.find("hold it fixed or add views"), std::string::npos) << message;
    }
  }
}

// A sample of the line, y = a x + b + p[0] + c, seen in one cluster (c: the
// cluster's held offset, as an image's held pose), its point's p[0] seen
// again in another cluster (p[0] = z); p[1], p[2] pinned. Linear, so the
// effect of a cluster's residuals on (a, b) is exact.
struct ClusterSample {
  ClusterSample(double x, const double* y) : x_(x), y_(y) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* p, const T* c, T* r) const {
    r[0] = a[0] * T(x_) + b[0] + p[0] + c[0] - T(*y_);
    r[1] = p[1] - T(0.1 * x_);
    r[2] = p[2] - T(0.2);
    return true;
  }
  double x_;
  const double* y_;
};
struct ClusterSecondLook {
  explicit ClusterSecondLook(const double* z) : z_(z) {}
  template <typename T>
  bool operator()(const T* p, const T* c, T* r) const {
    r[0] = p[0] + c[0] - T(*z_);
    return true;
  }
  const double* z_;
};

TEST(CalibrationCovariance, ClusteredCovarianceSumsEachClustersExactEffect) {
  // Linear least squares: moving cluster k's observations onto their fitted
  // values (its residuals to zero) moves the solution by exactly the
  // effect d_k = S^-1 u_k the clustered covariance sums; so clustered by
  // image it must equal V_image = G / (G - 1) * (N / (N - K)) * sum_k d_k
  // d_k', and clustered two ways V_image + V_track - V_image&track, each
  // with its own G. Sample i is seen in image i % 4 and again in image
  // (i + 1) % 4; its point is the track.
  constexpr int kSamples = 24, kImages = 4;
  std::vector<double> y(kSamples), z(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    // Errors that share a sign within an image and within a track (the
    // second look repeats part of the first one's error): what the
    // clustered covariance is for.
    const double shared = 0.01 * std::sin(3.0 * i);
    y[i] = 2.0 * i * 0.1 + 0.3 + 0.02 * ((i % kImages) - 1.5) + shared;
    z[i] = 0.05 * std::cos(1.7 * i) + 0.5 * shared;
  }
  double a = 0, b = 0;
  std::vector<std::array<double, 3>> p(kSamples, {0, 0, 0});
  std::array<double, kImages> offsets{};
  ceres::Problem problem;
  for (int i = 0; i < kSamples; ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ClusterSample, 3, 1, 1, 3, 1>(
                                 new ClusterSample(i * 0.1, &y[i])),
                             nullptr, &a, &b, p[i].data(), &offsets[i % kImages]);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<ClusterSecondLook, 1, 3, 1>(new ClusterSecondLook(&z[i])),
        nullptr, p[i].data(), &offsets[(i + 1) % kImages]);
  }
  for (double& offset : offsets) problem.SetParameterBlockConstant(&offset);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = options.gradient_tolerance = options.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  const auto solve = [&] {
    ceres::Solve(options, &problem, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable());
  };
  solve();
  const double a_hat = a, b_hat = b;
  const std::vector<double> y_observed = y, z_observed = z;
  const std::vector<std::array<double, 3>> p_hat = p;
  // The factor times the sum of d_k d_k' over `num_clusters` clusters, where
  // `in(k, i, second_look)` says whether an observation is in cluster k.
  constexpr double kResidualsPerDof = 1.25;
  const auto exact = [&](int num_clusters, const std::function<bool(int, int, bool)>& in) {
    Eigen::Matrix2d sum = Eigen::Matrix2d::Zero();
    for (int k = 0; k < num_clusters; ++k) {
      for (int i = 0; i < kSamples; ++i) {
        // Fitted values at the first solution.
        if (in(k, i, false)) y[i] = a_hat * i * 0.1 + b_hat + p_hat[i][0];
        if (in(k, i, true)) z[i] = p_hat[i][0];
      }
      solve();
      const Eigen::Vector2d effect(a - a_hat, b - b_hat);
      sum += effect * effect.transpose();
      // Back to the first solution and observations for the next cluster.
      y = y_observed;
      z = z_observed;
      a = a_hat;
      b = b_hat;
      p = p_hat;
    }
    return Eigen::Matrix2d(num_clusters / (num_clusters - 1.0) * kResidualsPerDof * sum);
  };
  const Eigen::Matrix2d by_image = exact(kImages, [](int k, int i, bool second) {
    return (second ? (i + 1) % kImages : i % kImages) == k;
  });
  const Eigen::Matrix2d by_track = exact(kSamples, [](int k, int i, bool) { return i == k; });
  const Eigen::Matrix2d by_both =
      exact(2 * kSamples, [](int k, int i, bool second) { return k == 2 * i + second; });
  const Eigen::Matrix2d two_way = by_image + by_track - by_both;
  // Not trivially zero: the clusters' errors moved the line; and positive
  // definite, so no eigenvalue is clipped.
  ASSERT_GT(by_image(0, 0), 1e-8);
  ASSERT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(two_way).eigenvalues().minCoeff(), 0.0);
  ASSERT_GT((two_way - by_image).norm(), 0.1 * by_image.norm());

  std::vector<double*> points;
  for (auto& q : p) points.push_back(q.data());
  ResidualClusters clusters;
  for (int k = 0; k < kImages; ++k) clusters.image_of_block[&offsets[k]] = k;
  clusters.residuals_per_dof = kResidualsPerDof;
  const auto describe = [](const double*, int) { return std::string("?"); };
  // Dense on one thread, sparse on two (the effects computed on both).
  for (const auto& [max_dense_size, threads] : {std::pair(1200, 1), std::pair(0, 2)}) {
    for (const bool two : {true, false}) {
      SCOPED_TRACE(std::string(two ? "two-way" : "by image") +
                   (max_dense_size == 0 ? ", sparse" : ", dense"));
      clusters.by_track = two;
      const MarginalCovariance marginal = ComputeMarginalCovariance(
          &problem, points, {&a, &b}, {&a, &b}, 1.0, describe, &clusters, max_dense_size, threads);
      const Eigen::Matrix2d& expected = two ? two_way : by_image;
      EXPECT_EQ(marginal.num_clusters, kImages);
      EXPECT_EQ(marginal.num_tracks, two ? kSamples : 0);
      ASSERT_EQ(marginal.clustered_covariance.rows(), 2);
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
          EXPECT_NEAR(marginal.clustered_covariance(i, j), expected(i, j), 1e-6 * expected.norm())
              << i << "," << j;
        }
      }
      EXPECT_NEAR(marginal.ClusteredStdDevs(&a)[0], std::sqrt(expected(0, 0)),
                  1e-6 * std::sqrt(expected(0, 0)));
    }
  }
  // Without clusters there is no clustered covariance.
  const MarginalCovariance plain =
      ComputeMarginalCovariance(&problem, points, {&a, &b}, {&a, &b}, 1.0, describe);
  EXPECT_EQ(plain.clustered_covariance.size(), 0);
  EXPECT_TRUE(plain.ClusteredStdDevs(&a).empty());
}

}  // namespace
}  // namespace portcal
