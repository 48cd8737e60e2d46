#include "pipelines/features/relative_pose_refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <memory>

namespace portcal {

namespace {

// From RANSAC's pose the five-parameter fit converges in a handful of
// steps; the limit only bounds the work on a bad start.
constexpr int kMaxNumIterations = 50;

// Sampson's distance of one match from the epipolar geometry E = [t]x R,
// in normalised coordinates: the first-order distance of (x1, x2) to the
// nearest pair that satisfies x2' E x1 = 0.
struct SampsonError {
  SampsonError(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) : x1_(x1), x2_(x2) {}

  // q: Eigen's quaternion order (x, y, z, w); t: the translation.
  template <typename T>
  bool operator()(const T* const q, const T* const t, T* residual) const {
    const Eigen::Quaternion<T> rotation(q[3], q[0], q[1], q[2]);
    const Eigen::Matrix<T, 3, 1> translation(t[0], t[1], t[2]);
    Eigen::Matrix<T, 3, 3> cross;
    cross << T(0), -translation.z(), translation.y(), translation.z(), T(0), -translation.x(),
        -translation.y(), translation.x(), T(0);
    const Eigen::Matrix<T, 3, 3> E = cross * rotation.toRotationMatrix();
    const Eigen::Matrix<T, 3, 1> p1(T(x1_.x()), T(x1_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> p2(T(x2_.x()), T(x2_.y()), T(1));
    const Eigen::Matrix<T, 3, 1> e_p1 = E * p1;
    const Eigen::Matrix<T, 3, 1> et_p2 = E.transpose() * p2;
    const T denominator =
        e_p1.x() * e_p1.x() + e_p1.y() * e_p1.y() + et_p2.x() * et_p2.x() + et_p2.y() * et_p2.y();
    // A match on the epipoles' line through both centres has no epipolar
    // distance to measure: fail rather than divide by zero.
    if (!(denominator > T(0))) return false;
    residual[0] = p2.dot(e_p1) / sqrt(denominator);
    return true;
  }

 private:
  Eigen::Vector2d x1_, x2_;
};

}  // namespace

std::optional<Rigid3d> RefineRelativePose(const std::vector<Eigen::Vector2d>& points1,
                                          const std::vector<Eigen::Vector2d>& points2,
                                          const Rigid3d& cam2_from_cam1, double loss_scale) {
  if (points1.size() != points2.size() || points1.size() < 5 || !(loss_scale >= 0))
    return std::nullopt;
  const double norm = cam2_from_cam1.translation.norm();
  if (!(norm > 0) || !std::isfinite(norm)) return std::nullopt;
  const Eigen::Quaterniond start = cam2_from_cam1.rotation.normalized();
  double q[4] = {start.x(), start.y(), start.z(), start.w()};
  Eigen::Vector3d t = cam2_from_cam1.translation / norm;
  // One loss for all residuals, deleted here, not by the problem.
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const std::unique_ptr<ceres::LossFunction> loss(loss_scale > 0 ? new ceres::CauchyLoss(loss_scale)
                                                                 : nullptr);
  for (size_t i = 0; i < points1.size(); ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SampsonError, 1, 4, 3>(
                                 new SampsonError(points1[i], points2[i])),
                             loss.get(), q, t.data());
  }
  problem.SetManifold(q, new ceres::EigenQuaternionManifold());
  problem.SetManifold(t.data(), new ceres::SphereManifold<3>());
  ceres::Solver::Options options;
  options.max_num_iterations = kMaxNumIterations;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;  // the matcher verifies pairs on all cores
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable() || summary.final_cost > summary.initial_cost) return std::nullopt;
  const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  if (!rotation.coeffs().allFinite() || !t.allFinite()) return std::nullopt;
  return Rigid3d(rotation.normalized(), t.normalized());
}

}  // namespace portcal
