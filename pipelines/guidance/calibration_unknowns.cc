#include "pipelines/guidance/calibration_unknowns.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/cost/board_reprojection_error.h"
#include "colmap_ext/cost/board_through_port_error.h"
#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/housing/housing_manifold.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/util/error.h"

namespace portcal {

void CalibrationUnknowns::Check() const {
  if (housing_calibration && !camera.housing) {
    throw InputError("next-pose guidance: a housing calibration needs the housing's model and constants");
  }
  camera.camera.Validate("next-pose guidance: camera");
  for (int index : fixed_intrinsics) {
    if (index < 0 || index >= static_cast<int>(camera.camera.params.size())) {
      throw InputError("next-pose guidance: held intrinsic " + std::to_string(index) + " is not a parameter of " +
                       camera.camera.ModelName());
    }
  }
}

int CalibrationUnknowns::NumUnknowns() const {
  if (!housing_calibration) {
    return static_cast<int>(camera.camera.params.size() - fixed_intrinsics.size());
  }
  const HousingRefinement refinement = camera.housing->Refinement();
  return (refinement.orientation.empty() ? 0 : 2) + static_cast<int>(refinement.position.size());
}

namespace {

// One problem over a pose and the unknowns, with the residuals of target
// points that project; Evaluate gives the Jacobian in the tangent spaces.
class PointProblem {
 public:
  PointProblem(const CalibrationUnknowns& unknowns, const Rigid3d& cam_from_target)
      : unknowns_(unknowns), pose_(ToPose(cam_from_target)), intrinsics_(unknowns.camera.camera.params) {
    if (unknowns.camera.housing) housing_ = unknowns.camera.housing->params;
  }

  // Adds the points that project; returns their indices.
  std::vector<int> AddPoints(const std::vector<Eigen::Vector3d>& points) {
    std::vector<int> added;
    const Rigid3d cam_from_target = FromPose(pose_);
    VisitCameraModel(unknowns_.camera.camera.model_id, [&](auto camera_tag) {
      using CameraModel = decltype(camera_tag);
      for (size_t i = 0; i < points.size(); ++i) {
        if (!unknowns_.camera.Project(cam_from_target * points[i])) continue;
        added.push_back(static_cast<int>(i));
        if (!unknowns_.camera.housing) {
          problem_.AddResidualBlock(BoardReprojectionError<CameraModel>::Create(
                                        points[i], Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()),
                                    nullptr, pose_.data(), intrinsics_.data(), warp_.data());
          continue;
        }
        VisitHousingModel(unknowns_.camera.housing->model_id, [&](auto port_tag) {
          using Functor = BoardThroughPortError<CameraModel, decltype(port_tag), PortErrorKind::kReprojection>;
          problem_.AddResidualBlock(Functor::Create(points[i], Eigen::Vector2d::Zero()), nullptr, pose_.data(),
                                    intrinsics_.data(), housing_.data());
        });
      }
    });
    return added;
  }

  // The Jacobian's columns: the pose's 6 (when `with_pose`), then the
  // unknowns'. Empty without residuals.
  Eigen::MatrixXd Jacobian(bool with_pose) {
    if (problem_.NumResidualBlocks() == 0) return Eigen::MatrixXd();
    problem_.SetManifold(pose_.data(), PoseManifold());
    ceres::Problem::EvaluateOptions options;
    if (with_pose) options.parameter_blocks.push_back(pose_.data());
    if (double* block = UnknownBlock()) options.parameter_blocks.push_back(block);
    if (options.parameter_blocks.empty()) return Eigen::MatrixXd();
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
      problem_.SetManifold(intrinsics_.data(), new ceres::SubsetManifold(n, unknowns_.fixed_intrinsics));
    }
    return intrinsics_.data();
  }

  const CalibrationUnknowns& unknowns_;
  ceres::Problem problem_;
  PoseBlock pose_;
  std::vector<double> intrinsics_;
  std::vector<double> housing_;
  std::array<double, 2> warp_ = {0, 0};  // a flat board
};

}  // namespace

Eigen::MatrixXd ViewInformation(const CalibrationUnknowns& unknowns,
                                const std::vector<Eigen::Vector3d>& points_in_target,
                                const Rigid3d& cam_from_target) {
  const int p = unknowns.NumUnknowns();
  PointProblem problem(unknowns, cam_from_target);
  problem.AddPoints(points_in_target);
  const Eigen::MatrixXd jacobian = problem.Jacobian(true);
  if (jacobian.rows() < 6 || p == 0) return Eigen::MatrixXd::Zero(p, p);
  const Eigen::MatrixXd pose_columns = jacobian.leftCols(6);
  const Eigen::MatrixXd unknown_columns = jacobian.rightCols(p);
  const Eigen::MatrixXd b = pose_columns.transpose() * pose_columns;
  const Eigen::MatrixXd c = unknown_columns.transpose() * pose_columns;
  const Eigen::MatrixXd a = unknown_columns.transpose() * unknown_columns;
  // A pose that the view does not fix (three points) carries nothing.
  const Eigen::LDLT<Eigen::MatrixXd> pose_information(b);
  if (pose_information.info() != Eigen::Success || pose_information.vectorD().minCoeff() <= 1e-12 * b.trace()) {
    return Eigen::MatrixXd::Zero(p, p);
  }
  const Eigen::MatrixXd reduced = a - c * pose_information.solve(c.transpose());
  return 0.5 * (reduced + reduced.transpose());
}

Eigen::MatrixXd ProjectionJacobian(const CalibrationUnknowns& unknowns,
                                   const std::vector<Eigen::Vector3d>& points_in_cam) {
  const int p = unknowns.NumUnknowns();
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(2 * static_cast<Eigen::Index>(points_in_cam.size()), p);
  PointProblem problem(unknowns, Rigid3d());
  const std::vector<int> added = problem.AddPoints(points_in_cam);
  const Eigen::MatrixXd jacobian = problem.Jacobian(false);
  if (jacobian.size() == 0) return result;
  for (size_t k = 0; k < added.size(); ++k) {
    result.middleRows(2 * added[k], 2) = jacobian.middleRows(2 * static_cast<Eigen::Index>(k), 2);
  }
  return result;
}

}  // namespace portcal
