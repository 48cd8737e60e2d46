#include "pipelines/guidance/calibration_unknowns.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_reprojection_error.h"
#include "colmap_ext/cost/board_through_port_error.h"
#include "colmap_ext/cost/board_warp.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {

void CalibrationUnknowns::Check() const {
  if (housing_calibration && !camera.housing) {
    throw InputError(
        "next-pose guidance: a housing calibration needs the housing's model and constants");
  }
  if (camera.housing && board_warp) {
    throw InputError("next-pose guidance: behind a housing the board is held flat (no board warp)");
  }
  camera.camera.Validate("next-pose guidance: camera");
  for (int index : fixed_intrinsics) {
    if (index < 0 || index >= static_cast<int>(camera.camera.params.size())) {
      throw InputError("next-pose guidance: held intrinsic " + std::to_string(index) +
                       " is not a parameter of " + camera.camera.ModelName());
    }
  }
}

int CalibrationUnknowns::NumUnknowns() const {
  if (!housing_calibration) {
    return static_cast<int>(camera.camera.params.size() - fixed_intrinsics.size()) +
           (board_warp && !camera.housing ? 2 : 0);
  }
  const HousingRefinement refinement = camera.housing->Refinement();
  return (refinement.orientation.empty() ? 0 : 2) + static_cast<int>(refinement.position.size());
}

namespace {

// One problem over a pose and the unknowns, with the residuals of points
// that project; Evaluate gives the Jacobian in the tangent spaces.
class PointProblem {
 public:
  PointProblem(const CalibrationUnknowns& unknowns, const Rigid3d& cam_from_target)
      : unknowns_(unknowns),
        pose_(ToPose(cam_from_target)),
        intrinsics_(unknowns.camera.camera.params) {
    if (unknowns.camera.housing) housing_ = unknowns.camera.housing->params;
    if (unknowns.board_warp)
      warp_ = {unknowns.board_warp->value.x(), unknowns.board_warp->value.y()};
  }

  // Adds the points that project; returns their indices. Target points
  // (`on_board`) sag with the board's warp; others do not.
  std::vector<int> AddPoints(const std::vector<Eigen::Vector3d>& points, bool on_board) {
    std::vector<int> added;
    const Rigid3d cam_from_target = FromPose(pose_);
    VisitCameraModel(unknowns_.camera.camera.model_id, [&](auto camera_tag) {
      using CameraModel = decltype(camera_tag);
      for (size_t i = 0; i < points.size(); ++i) {
        if (!unknowns_.camera.Project(cam_from_target * points[i])) continue;
        added.push_back(static_cast<int>(i));
        if (!unknowns_.camera.housing) {
          // (u, v) = (1, 1) is where the sag and its derivatives vanish.
          const Eigen::Vector2d uv = on_board && unknowns_.board_warp
                                         ? BoardWarpUv(points[i], unknowns_.board_warp->extent)
                                         : Eigen::Vector2d(1, 1);
          problem_.AddResidualBlock(
              BoardReprojectionError<CameraModel>::Create(points[i], uv, Eigen::Vector2d::Zero()),
              nullptr, pose_.data(), intrinsics_.data(), warp_.data());
          continue;
        }
        VisitHousingModel(unknowns_.camera.housing->model_id, [&](auto port_tag) {
          using Functor =
              BoardThroughPortError<CameraModel, decltype(port_tag), PortErrorKind::kReprojection>;
          problem_.AddResidualBlock(Functor::Create(points[i], Eigen::Vector2d::Zero()), nullptr,
                                    pose_.data(), intrinsics_.data(), housing_.data());
        });
      }
    });
    return added;
  }

  // The Jacobian's columns: the pose's 6, then the unknowns' (the board
  // warp's last, when `with_warp` and it is an unknown). Empty without
  // residuals.
  Eigen::MatrixXd Jacobian(bool with_warp) {
    if (problem_.NumResidualBlocks() == 0) return Eigen::MatrixXd();
    problem_.SetManifold(pose_.data(), PoseManifold());
    ceres::Problem::EvaluateOptions options;
    options.parameter_blocks.push_back(pose_.data());
    if (double* block = UnknownBlock()) options.parameter_blocks.push_back(block);
    if (with_warp && unknowns_.board_warp && !unknowns_.camera.housing) {
      options.parameter_blocks.push_back(warp_.data());
    }
    ceres::CRSMatrix crs;
    if (!problem_.Evaluate(options, nullptr, nullptr, nullptr, &crs)) {
      throw NumericalError("next-pose guidance: the Jacobian of a view could not be evaluated");
    }
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) dense(r, crs.cols[k]) = crs.values[k];
    }
    return dense;
  }

 private:
  // The block of the unknowns with its manifold set (nullptr when all of it
  // is held).
  double* UnknownBlock() {
    if (unknowns_.housing_calibration) {
      SetHousingRefinement(*unknowns_.camera.housing, true, housing_.data(), &problem_);
      return unknowns_.NumUnknowns() > 0 ? housing_.data() : nullptr;
    }
    const int n = static_cast<int>(intrinsics_.size());
    if (static_cast<int>(unknowns_.fixed_intrinsics.size()) >= n) return nullptr;
    if (!unknowns_.fixed_intrinsics.empty()) {
      problem_.SetManifold(intrinsics_.data(),
                           new ceres::SubsetManifold(n, unknowns_.fixed_intrinsics));
    }
    return intrinsics_.data();
  }

  const CalibrationUnknowns& unknowns_;
  ceres::Problem problem_;
  PoseBlock pose_;
  std::vector<double> intrinsics_;
  std::vector<double> housing_;
  std::array<double, 2> warp_ = {0, 0};  // a flat board unless the warp is an unknown
};

}  // namespace

CalibrationInformation ViewInformation(const CalibrationUnknowns& unknowns,
                                       const std::vector<Eigen::Vector3d>& points_in_target,
                                       const Rigid3d& cam_from_target) {
  const int p = unknowns.NumUnknowns();
  PointProblem problem(unknowns, cam_from_target);
  problem.AddPoints(points_in_target, true);
  const Eigen::MatrixXd jacobian = problem.Jacobian(true);
  if (jacobian.rows() < 6 || p == 0) return CalibrationInformation::Zero(p);
  PORTCAL_CHECK(jacobian.cols() == 6 + p);
  const Eigen::MatrixXd pose_columns = jacobian.leftCols(6);
  const Eigen::MatrixXd unknown_columns = jacobian.rightCols(p);
  return CalibrationInformation::OfView(
      pose_columns.transpose() * pose_columns, unknown_columns.transpose() * unknown_columns,
      unknown_columns.transpose() * pose_columns, cam_from_target.translation);
}

ProjectionJacobians ProjectionJacobian(const CalibrationUnknowns& unknowns,
                                       const std::vector<Eigen::Vector3d>& points_in_cam) {
  const int p = unknowns.NumUnknowns();
  const Eigen::Index rows = 2 * static_cast<Eigen::Index>(points_in_cam.size());
  ProjectionJacobians result{Eigen::MatrixXd::Zero(rows, p), Eigen::MatrixXd::Zero(rows, 3)};
  // At the identity pose, the pose's translation step moves the point
  // itself: its columns are d pixel / d point.
  PointProblem problem(unknowns, Rigid3d());
  const std::vector<int> added = problem.AddPoints(points_in_cam, false);
  const Eigen::MatrixXd jacobian = problem.Jacobian(false);
  if (jacobian.size() == 0) return result;
  const Eigen::Index unknown_columns = jacobian.cols() - 6;  // the warp's columns stay zero
  for (size_t k = 0; k < added.size(); ++k) {
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(k), to = 2 * added[k];
    result.point.middleRows(to, 2) = jacobian.block(row, 3, 2, 3);
    result.unknowns.block(to, 0, 2, unknown_columns) = jacobian.block(row, 6, 2, unknown_columns);
  }
  return result;
}

}  // namespace portcal
