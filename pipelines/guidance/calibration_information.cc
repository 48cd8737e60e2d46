#include "pipelines/guidance/calibration_information.h"

#include <Eigen/Cholesky>

namespace portcal {
namespace {

Eigen::Matrix3d Cross(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

CalibrationInformation CalibrationInformation::Zero(int num_unknowns) {
  CalibrationInformation information;
  information.reduced = Eigen::MatrixXd::Zero(num_unknowns, num_unknowns);
  information.k_rotation = Eigen::MatrixXd::Zero(3, num_unknowns);
  information.k_offset = Eigen::MatrixXd::Zero(3, num_unknowns);
  return information;
}

CalibrationInformation CalibrationInformation::OfView(const Eigen::MatrixXd& pose_pose,
                                                      const Eigen::MatrixXd& unknowns_unknowns,
                                                      const Eigen::MatrixXd& unknowns_pose,
                                                      const Eigen::Vector3d& translation) {
  const int p = static_cast<int>(unknowns_unknowns.rows());
  CalibrationInformation information = Zero(p);
  // A pose that the view does not fix (three points) carries nothing.
  const Eigen::LDLT<Eigen::MatrixXd> pose_information(pose_pose);
  if (pose_information.info() != Eigen::Success ||
      !(pose_information.vectorD().minCoeff() > 1e-12 * pose_pose.trace())) {
    return information;
  }
  const Eigen::MatrixXd k = pose_information.solve(unknowns_pose.transpose());  // 6 x p
  Eigen::MatrixXd covariance = pose_information.solve(Eigen::MatrixXd::Identity(6, 6));
  covariance = 0.5 * (covariance + covariance.transpose());
  const Eigen::MatrixXd reduced = unknowns_unknowns - unknowns_pose * k;
  information.reduced = 0.5 * (reduced + reduced.transpose());
  information.num_views = 1;
  const Eigen::Matrix3d t = 2 * Cross(translation);
  const Eigen::Matrix3d p_rr = covariance.topLeftCorner<3, 3>();
  const Eigen::Matrix3d p_rt = covariance.topRightCorner<3, 3>();
  information.k_rotation = k.topRows(3);
  information.k_offset = t * k.topRows(3) + k.bottomRows(3);
  information.p_rr = p_rr;
  information.p_rr_t = p_rr * t.transpose();
  information.t_p_rr_t = t * p_rr * t.transpose();
  information.p_rt = p_rt;
  information.t_p_rt = t * p_rt;
  information.p_tt = covariance.bottomRightCorner<3, 3>();
  return information;
}

CalibrationInformation& CalibrationInformation::operator+=(const CalibrationInformation& other) {
  reduced += other.reduced;
  num_views += other.num_views;
  k_rotation += other.k_rotation;
  k_offset += other.k_offset;
  p_rr += other.p_rr;
  p_rr_t += other.p_rr_t;
  t_p_rr_t += other.t_p_rr_t;
  p_rt += other.p_rt;
  t_p_rt += other.t_p_rt;
  p_tt += other.p_tt;
  return *this;
}

CalibrationInformation CalibrationInformation::operator+(
    const CalibrationInformation& other) const {
  CalibrationInformation sum = *this;
  sum += other;
  return sum;
}

Eigen::MatrixXd CalibrationInformation::MeanFrameGain(const Eigen::Vector3d& p) const {
  if (num_views == 0) return Eigen::MatrixXd::Zero(3, NumUnknowns());
  return (-2 * Cross(p) * k_rotation + k_offset) / num_views;
}

Eigen::Matrix3d CalibrationInformation::MeanFrameNoise(const Eigen::Vector3d& p) const {
  if (num_views == 0) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d a = -2 * Cross(p);
  const Eigen::Matrix3d rotation_part =
      a * p_rr * a.transpose() + a * p_rr_t + (a * p_rr_t).transpose() + t_p_rr_t;
  const Eigen::Matrix3d cross_part = a * p_rt + t_p_rt;
  return (rotation_part + cross_part + cross_part.transpose() + p_tt) /
         (static_cast<double>(num_views) * num_views);
}

}  // namespace portcal
