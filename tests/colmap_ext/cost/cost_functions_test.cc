// The refractive residuals: Jet derivatives against central differences,
// zero at the truth, and agreement of the two errors near the optimum.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/refractive_reproj_error.h"
#include "colmap_ext/cost/virtual_camera_error.h"
#include "colmap_ext/housing/housing.h"
#include "colmap_ext/housing/housing_models.h"

namespace portcal {
namespace {

struct Scene {
  std::vector<double> intrinsics = {1297.3655, 961.3, 538.2, -0.05, 0.01};
  std::vector<double> housing;
  std::array<double, 7> cam_from_world;  // qx qy qz qw tx ty tz
  std::array<double, 3> point_in_world = {0.12, -0.08, 0.04};
  Eigen::Vector2d observed;
};

template <typename Port>
Scene MakeScene(const std::vector<double>& housing) {
  Scene scene;
  scene.housing = housing;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, 1, -0.2).normalized()));
  scene.cam_from_world = {q.x(), q.y(), q.z(), q.w(), -0.05, 0.1, 0.9};
  const Eigen::Vector3d point_in_cam =
      q * Eigen::Vector3d(scene.point_in_world.data()) + Eigen::Vector3d(-0.05, 0.1, 0.9);
  EXPECT_TRUE((ImgFromWater<RadialModel, Port, double>(scene.intrinsics.data(),
                                                       scene.housing.data(), point_in_cam,
                                                       &scene.observed.x(), &scene.observed.y())));
  return scene;
}

const std::vector<double> kFlat = {0.0871557, 0, 0.9961947, 0.02, 0.014, 1.0, 1.473, 1.334};
const std::vector<double> kDome = {0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334};

// Compares the analytic (autodiff) Jacobians of a cost function with
// central differences in every parameter block.
void CheckJacobians(ceres::CostFunction* cost, std::vector<double*> blocks,
                    const std::vector<int>& sizes) {
  std::unique_ptr<ceres::CostFunction> owner(cost);
  double residual[2];
  std::vector<std::vector<double>> jacobians(blocks.size());
  std::vector<double*> jacobian_ptrs;
  for (size_t b = 0; b < blocks.size(); ++b) {
    jacobians[b].resize(2 * sizes[b]);
    jacobian_ptrs.push_back(jacobians[b].data());
  }
  ASSERT_TRUE(cost->Evaluate(blocks.data(), residual, jacobian_ptrs.data()));
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int k = 0; k < sizes[b]; ++k) {
      const double saved = blocks[b][k];
      const double h = 1e-7 * std::max(1.0, std::abs(saved));
      double plus[2], minus[2];
      blocks[b][k] = saved + h;
      ASSERT_TRUE(cost->Evaluate(blocks.data(), plus, nullptr));
      blocks[b][k] = saved - h;
      ASSERT_TRUE(cost->Evaluate(blocks.data(), minus, nullptr));
      blocks[b][k] = saved;
      for (int r = 0; r < 2; ++r) {
        const double numeric = (plus[r] - minus[r]) / (2 * h);
        const double analytic = jacobians[b][r * sizes[b] + k];
        EXPECT_NEAR(analytic, numeric, 1e-4 * (1.0 + std::abs(numeric)))
            << "block " << b << " param " << k << " residual " << r;
      }
    }
  }
}

template <typename Port, template <typename, typename> class Error>
void CheckErrorJacobians(const std::vector<double>& housing) {
  Scene scene = MakeScene<Port>(housing);
  // Off the optimum so that every Jacobian entry matters.
  scene.point_in_world[0] += 0.003;
  CheckJacobians(Error<RadialModel, Port>::Create(scene.observed, 0.5),
                 {scene.cam_from_world.data(), scene.point_in_world.data(), scene.intrinsics.data(),
                  scene.housing.data()},
                 {7, 3, RadialModel::kNumParams, Port::kNumParams});
}

TEST(CostFunctions, ReprojErrorJacobiansMatchCentralDifferences) {
  CheckErrorJacobians<FlatPort, RefractiveReprojError>(kFlat);
  CheckErrorJacobians<DomePort, RefractiveReprojError>(kDome);
}

TEST(CostFunctions, VirtualCameraErrorJacobiansMatchCentralDifferences) {
  CheckErrorJacobians<FlatPort, VirtualCameraError>(kFlat);
  CheckErrorJacobians<DomePort, VirtualCameraError>(kDome);
}

template <typename Port, template <typename, typename> class Error>
Eigen::Vector2d Residual(Scene scene) {
  std::unique_ptr<ceres::CostFunction> cost(Error<RadialModel, Port>::Create(scene.observed, 1.0));
  const double* blocks[] = {scene.cam_from_world.data(), scene.point_in_world.data(),
                            scene.intrinsics.data(), scene.housing.data()};
  Eigen::Vector2d residual;
  EXPECT_TRUE(cost->Evaluate(blocks, residual.data(), nullptr));
  return residual;
}

template <typename Port>
void CheckErrorsAgree(const std::vector<double>& housing) {
  const Scene scene = MakeScene<Port>(housing);
  // Both vanish at the truth.
  EXPECT_LT((Residual<Port, RefractiveReprojError>(scene)).norm(), 1e-8);
  EXPECT_LT((Residual<Port, VirtualCameraError>(scene)).norm(), 1e-8);
  // Near it they measure the same displacement: same direction, a scale
  // within the refractive magnification (nw / na ~ 1.33) of each other.
  for (const Eigen::Vector3d& delta : {Eigen::Vector3d(1e-3, 0, 0), Eigen::Vector3d(0, -1e-3, 0),
                                       Eigen::Vector3d(7e-4, 7e-4, 0)}) {
    Scene moved = scene;
    for (int i = 0; i < 3; ++i) moved.point_in_world[i] += delta[i];
    const Eigen::Vector2d reproj = Residual<Port, RefractiveReprojError>(moved);
    const Eigen::Vector2d virtual_px = Residual<Port, VirtualCameraError>(moved);
    EXPECT_GT(reproj.normalized().dot(virtual_px.normalized()), 0.97) << Port::kName;
    const double ratio = virtual_px.norm() / reproj.norm();
    EXPECT_GT(ratio, 0.6) << Port::kName;
    EXPECT_LT(ratio, 1.6) << Port::kName;
  }
}

TEST(CostFunctions, VirtualCameraAndReprojectionErrorsAgreeNearTheOptimum) {
  CheckErrorsAgree<FlatPort>(kFlat);
  CheckErrorsAgree<DomePort>(kDome);
}

// Triangulating one point from several views behind a dome with either
// error lands on the truth (noise-free), from a start 5 cm off.
template <template <typename, typename> class Error>
Eigen::Vector3d TriangulateBehindDome() {
  const std::vector<double> intrinsics = {1297.3655, 961.3, 538.2, -0.05, 0.01};
  std::vector<double> housing = kDome;
  const Eigen::Vector3d truth(0.05, -0.03, 1.1);
  std::vector<std::array<double, 7>> poses;
  ceres::Problem problem;
  Eigen::Vector3d estimate = truth + Eigen::Vector3d(0.05, -0.04, 0.05);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.1 * i - 0.15, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d t(0.1 * i - 0.15, 0.02 * i, 0.05);
    poses.push_back({q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()});
  }
  for (auto& pose : poses) {
    const Eigen::Quaterniond q(pose[3], pose[0], pose[1], pose[2]);
    Eigen::Vector2d observed;
    EXPECT_TRUE((ImgFromWater<RadialModel, DomePort, double>(
        intrinsics.data(), housing.data(),
        Eigen::Vector3d(q * truth + Eigen::Vector3d(pose[4], pose[5], pose[6])), &observed.x(),
        &observed.y())));
    problem.AddResidualBlock(Error<RadialModel, DomePort>::Create(observed, 1.0), nullptr,
                             pose.data(), estimate.data(), const_cast<double*>(intrinsics.data()),
                             housing.data());
    problem.SetParameterBlockConstant(pose.data());
  }
  problem.SetParameterBlockConstant(intrinsics.data());
  problem.SetParameterBlockConstant(housing.data());
  ceres::Solver::Options options;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable());
  return estimate;
}

TEST(CostFunctions, BothErrorsTriangulateToTheTruth) {
  const Eigen::Vector3d truth(0.05, -0.03, 1.1);
  EXPECT_LT((TriangulateBehindDome<RefractiveReprojError>() - truth).norm(), 1e-9);
  EXPECT_LT((TriangulateBehindDome<VirtualCameraError>() - truth).norm(), 1e-9);
}

TEST(CostFunctions, UnprojectablePointsFailInsteadOfReturningZeros) {
  Scene scene = MakeScene<FlatPort>(kFlat);
  scene.point_in_world = {0, 0, -5};  // behind the camera
  std::unique_ptr<ceres::CostFunction> cost(
      RefractiveReprojError<RadialModel, FlatPort>::Create(scene.observed, 1.0));
  const double* blocks[] = {scene.cam_from_world.data(), scene.point_in_world.data(),
                            scene.intrinsics.data(), scene.housing.data()};
  double residual[2];
  EXPECT_FALSE(cost->Evaluate(blocks, residual, nullptr));
  std::unique_ptr<ceres::CostFunction> virtual_cost(
      VirtualCameraError<RadialModel, FlatPort>::Create(scene.observed, 1.0));
  EXPECT_FALSE(virtual_cost->Evaluate(blocks, residual, nullptr));
}

}  // namespace
}  // namespace portcal
