// The mean-frames projection uncertainty: the O(1)-per-point form
// (calibration_information.h) against the dense textbook one (the full
// state's covariance, every frame's Jacobian evaluated by Ceres), for a lens
// with held parameters and a board warp, and for a dome port; and
// information that adds up view by view.
#include "pipelines/guidance/projection_uncertainty.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_reprojection_error.h"
#include "colmap_ext/cost/board_through_port_error.h"
#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/housing/housing_models.h"

namespace portcal {
namespace {

std::vector<Eigen::Vector3d> BoardPoints() {
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 9; ++c) points.emplace_back(0.03 * c, 0.03 * r, 0);
  }
  return points;
}

std::vector<Rigid3d> Poses() {
  std::vector<Rigid3d> poses;
  const double angles[][3] = {
      {0, 0, 0}, {0.5, 0, 0.1}, {0, -0.5, 0}, {0.3, 0.4, -0.2}, {-0.4, 0.2, 0.3}};
  for (const auto& a : angles) {
    const Eigen::Quaterniond q = Eigen::AngleAxisd(a[0], Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(a[1], Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(a[2], Eigen::Vector3d::UnitZ());
    // The board's centre (0.12, 0.075) at ~0.5 m, a little off the axis.
    poses.emplace_back(
        q, Eigen::Vector3d(0.02 * a[1], -0.03 * a[0], 0.5) - q * Eigen::Vector3d(0.12, 0.075, 0));
  }
  return poses;
}

// The dense Jacobian of every corner of every view: columns the poses' 6
// tangent each, then the unknowns (intrinsics not held or the housing's
// refined parameters, then the board warp).
Eigen::MatrixXd DenseJacobian(const CalibrationUnknowns& unknowns,
                              const std::vector<Rigid3d>& poses) {
  ceres::Problem problem;
  std::vector<PoseBlock> blocks;
  for (const Rigid3d& pose : poses) blocks.push_back(ToPose(pose));
  std::vector<double> intrinsics = unknowns.camera.camera.params;
  std::vector<double> housing =
      unknowns.camera.housing ? unknowns.camera.housing->params : std::vector<double>();
  std::array<double, 2> warp = {0, 0};
  if (unknowns.board_warp) warp = {unknowns.board_warp->value.x(), unknowns.board_warp->value.y()};
  const std::vector<Eigen::Vector3d> points = BoardPoints();
  VisitCameraModel(unknowns.camera.camera.model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    for (PoseBlock& block : blocks) {
      for (const Eigen::Vector3d& p : points) {
        if (!unknowns.camera.housing) {
          const Eigen::Vector2d uv = unknowns.board_warp
                                         ? BoardWarpUv(p, unknowns.board_warp->extent)
                                         : Eigen::Vector2d(1, 1);
          problem.AddResidualBlock(
              BoardReprojectionError<CameraModel>::Create(p, uv, Eigen::Vector2d::Zero()), nullptr,
              block.data(), intrinsics.data(), warp.data());
          continue;
        }
        VisitHousingModel(unknowns.camera.housing->model_id, [&](auto port_tag) {
          using Functor =
              BoardThroughPortError<CameraModel, decltype(port_tag), PortErrorKind::kReprojection>;
          problem.AddResidualBlock(Functor::Create(p, Eigen::Vector2d::Zero()), nullptr,
                                   block.data(), intrinsics.data(), housing.data());
        });
      }
    }
  });
  ceres::Problem::EvaluateOptions options;
  for (PoseBlock& block : blocks) {
    problem.SetManifold(block.data(), PoseManifold());
    options.parameter_blocks.push_back(block.data());
  }
  if (unknowns.housing_calibration) {
    SetHousingRefinement(*unknowns.camera.housing, true, housing.data(), &problem);
    options.parameter_blocks.push_back(housing.data());
  } else {
    const int n = static_cast<int>(intrinsics.size());
    if (!unknowns.fixed_intrinsics.empty()) {
      problem.SetManifold(intrinsics.data(),
                          new ceres::SubsetManifold(n, unknowns.fixed_intrinsics));
    }
    options.parameter_blocks.push_back(intrinsics.data());
    if (unknowns.board_warp) options.parameter_blocks.push_back(warp.data());
  }
  ceres::CRSMatrix crs;
  EXPECT_TRUE(problem.Evaluate(options, nullptr, nullptr, nullptr, &crs));
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) dense(r, crs.cols[k]) = crs.values[k];
  }
  return dense;
}

// d pixel / d pose (2 x 6, tangent) of a point fixed in the target frame.
Eigen::Matrix<double, 2, 6> PoseJacobian(const CalibrationUnknowns& unknowns, const Rigid3d& pose,
                                         const Eigen::Vector3d& point_in_target) {
  ceres::Problem problem;
  PoseBlock block = ToPose(pose);
  std::vector<double> intrinsics = unknowns.camera.camera.params;
  std::vector<double> housing =
      unknowns.camera.housing ? unknowns.camera.housing->params : std::vector<double>();
  std::array<double, 2> warp = {0, 0};
  VisitCameraModel(unknowns.camera.camera.model_id, [&](auto camera_tag) {
    using CameraModel = decltype(camera_tag);
    if (!unknowns.camera.housing) {
      problem.AddResidualBlock(BoardReprojectionError<CameraModel>::Create(
                                   point_in_target, Eigen::Vector2d(1, 1), Eigen::Vector2d::Zero()),
                               nullptr, block.data(), intrinsics.data(), warp.data());
      return;
    }
    VisitHousingModel(unknowns.camera.housing->model_id, [&](auto port_tag) {
      using Functor =
          BoardThroughPortError<CameraModel, decltype(port_tag), PortErrorKind::kReprojection>;
      problem.AddResidualBlock(Functor::Create(point_in_target, Eigen::Vector2d::Zero()), nullptr,
                               block.data(), intrinsics.data(), housing.data());
    });
  });
  problem.SetManifold(block.data(), PoseManifold());
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks.push_back(block.data());
  ceres::CRSMatrix crs;
  EXPECT_TRUE(problem.Evaluate(options, nullptr, nullptr, nullptr, &crs));
  Eigen::Matrix<double, 2, 6> dense = Eigen::Matrix<double, 2, 6>::Zero();
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) dense(r, crs.cols[k]) = crs.values[k];
  }
  return dense;
}

// mrcal's definition, written out: Var(q) = sigma^2 G (J'J)^-1 G', G the
// derivative of the pixel of a point mapped into every frame with the
// solved pose, back with the perturbed one, averaged.
double DenseWorstDirection(const CalibrationUnknowns& unknowns, const std::vector<Rigid3d>& poses,
                           const Eigen::Vector3d& point_in_cam, double sigma) {
  const Eigen::MatrixXd jacobian = DenseJacobian(unknowns, poses);
  const Eigen::MatrixXd covariance = sigma * sigma * (jacobian.transpose() * jacobian).inverse();
  const int n = static_cast<int>(poses.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2, jacobian.cols());
  for (int i = 0; i < n; ++i) {
    g.middleCols(6 * i, 6) =
        PoseJacobian(unknowns, poses[i], poses[i].Inverse() * point_in_cam) / n;
  }
  const ProjectionJacobians at_point = ProjectionJacobian(unknowns, {point_in_cam});
  g.rightCols(unknowns.NumUnknowns()) = at_point.unknowns;
  const Eigen::Matrix2d var = g * covariance * g.transpose();
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(var).eigenvalues().maxCoeff());
}

// The model's map against the dense definition at every grid point, at the
// working distance and (a point 1e6 m out) at infinity.
void ExpectEqualsDense(const CalibrationUnknowns& unknowns) {
  const std::vector<Rigid3d> poses = Poses();
  CalibrationInformation information = CalibrationInformation::Zero(unknowns.NumUnknowns());
  for (const Rigid3d& pose : poses) information += ViewInformation(unknowns, BoardPoints(), pose);
  ASSERT_EQ(information.num_views, static_cast<int>(poses.size()));
  ProjectionUncertaintyOptions options;
  options.grid_cols = 4;
  options.grid_rows = 3;
  options.working_distance_m = 0.7;
  options.pixel_sigma_px = 0.3;
  const ProjectionUncertainty model =
      ProjectionUncertaintyModel(unknowns, options).Evaluate(information);
  ASSERT_TRUE(model.determined);
  const Eigen::VectorXd xs =
      UncertaintyGridColumns(static_cast<double>(unknowns.camera.camera.width), 4);
  const Eigen::VectorXd ys =
      UncertaintyGridRows(static_cast<double>(unknowns.camera.camera.height), 3);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      const std::optional<Ray3d> ray = unknowns.camera.Unproject(Eigen::Vector2d(xs[c], ys[r]));
      ASSERT_TRUE(ray);
      for (const double depth : {options.working_distance_m, 1e6}) {
        const Eigen::Vector3d point =
            ray->origin + (depth - ray->origin.z()) / ray->direction.z() * ray->direction;
        const double dense = DenseWorstDirection(unknowns, poses, point, options.pixel_sigma_px);
        const double fast = depth < 1e3 ? model.map_px(r, c) : model.map_at_infinity_px(r, c);
        EXPECT_NEAR(fast, dense, 1e-5 * dense)
            << "cell " << r << "," << c << " at " << depth << " m";
      }
    }
  }
  // The point fixed to the targets is never less certain than the point
  // fixed to the camera: the compensation only takes back error.
  EXPECT_GT(model.mean_px, 0);
}

Camera Lens() {
  Camera camera = Camera::FromModelName("OPENCV", 500, 640, 480);
  camera.params = {505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007};
  return camera;
}

TEST(MeanFrames, EqualsTheDenseDefinitionForALens) {
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = Lens();
  ExpectEqualsDense(unknowns);
}

TEST(MeanFrames, EqualsTheDenseDefinitionWithHeldParametersAndABoardWarp) {
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = Lens();
  unknowns.fixed_intrinsics = {6, 7};  // p1, p2 held
  unknowns.board_warp =
      BoardWarpUnknown{Eigen::Vector2d(0.001, -0.0005), Eigen::Vector4d(0, 0.24, 0, 0.15)};
  EXPECT_EQ(unknowns.NumUnknowns(), 8);
  ExpectEqualsDense(unknowns);
}

TEST(MeanFrames, EqualsTheDenseDefinitionForADomePort) {
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = Lens();
  unknowns.camera.housing =
      Housing::FromName("DOMEPORT", {0.002, -0.001, 0.004, 0.05, 0.006, 1.0, 1.49, 1.334}, "test");
  unknowns.housing_calibration = true;
  ASSERT_EQ(unknowns.NumUnknowns(), 3);
  ExpectEqualsDense(unknowns);
}

TEST(MeanFrames, InformationAddsUpViewByView) {
  CalibrationUnknowns unknowns;
  unknowns.camera.camera = Lens();
  const std::vector<Rigid3d> poses = Poses();
  CalibrationInformation first = CalibrationInformation::Zero(8), rest = first;
  first += ViewInformation(unknowns, BoardPoints(), poses[0]);
  for (size_t i = 1; i < poses.size(); ++i)
    rest += ViewInformation(unknowns, BoardPoints(), poses[i]);
  const CalibrationInformation all = first + rest;
  EXPECT_EQ(all.num_views, 5);
  EXPECT_TRUE(all.reduced.isApprox(first.reduced + rest.reduced));
  // Two points do not fix a pose: the view adds nothing, not a frame.
  const std::vector<Eigen::Vector3d> board = BoardPoints();
  const std::vector<Eigen::Vector3d> two(board.begin(), board.begin() + 2);
  EXPECT_EQ(ViewInformation(unknowns, two, poses[1]).num_views, 0);
}

}  // namespace
}  // namespace portcal
