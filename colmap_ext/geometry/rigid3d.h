// Rigid transform b_from_a: X_b = rotation * X_a + translation. Quaternions
// live in Eigen's (x, y, z, w) storage in memory; files and database tables
// use COLMAP's (w, x, y, z), converted only by the two functions below.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace portcal {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation(rotation), translation(translation) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  // c_from_a = c_from_b * b_from_a (reads right to left).
  Rigid3d operator*(const Rigid3d& b_from_a) const {
    return Rigid3d(rotation * b_from_a.rotation, rotation * b_from_a.translation + translation);
  }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.inverse();
    return Rigid3d(inv, -(inv * translation));
  }
  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = rotation.toRotationMatrix();
    m.col(3) = translation;
    return m;
  }
};

// COLMAP order (w, x, y, z) <-> Eigen quaternion.
inline Eigen::Quaterniond QuaternionFromWxyz(const Eigen::Vector4d& wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}
inline Eigen::Vector4d QuaternionToWxyz(const Eigen::Quaterniond& q) {
  return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
}

}  // namespace portcal
