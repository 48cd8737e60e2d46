// Hartley's normalisation of image points before a linear (DLT) fit:
// "In defense of the eight-point algorithm", PAMI 1997.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace portcal {

// The similarity that moves the points' centroid to 0 and their mean
// distance from it to sqrt(2).
inline Eigen::Matrix3d HartleyNormalization(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double mean = 0;
  for (const auto& p : points) mean += (p - centroid).norm();
  mean /= static_cast<double>(points.size());
  const double s = mean > 0 ? std::sqrt(2.0) / mean : 1.0;
  Eigen::Matrix3d t;
  t << s, 0, -s * centroid.x(), 0, s, -s * centroid.y(), 0, 0, 1;
  return t;
}

}  // namespace portcal
