// A marker side's edge as a curve, and where two sides' curves meet: the
// pieces both marker-corner refinements (marker_edge_refinement.h,
// marker_edge_crossings.h) intersect.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <optional>

namespace portcal {

// Side i of the quad `c` (c[i] -> c[i+1]): its start, length, unit
// direction and outward normal.
struct QuadSide {
  Eigen::Vector2d a, u, n;
  double length = 0;
};
inline QuadSide SideOfQuad(const std::array<Eigen::Vector2d, 4>& c, int i) {
  const Eigen::Vector2d centroid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  QuadSide side;
  side.a = c[i];
  const Eigen::Vector2d b = c[(i + 1) % 4];
  side.length = (b - side.a).norm();
  side.u = (b - side.a) / side.length;
  side.n = Eigen::Vector2d(-side.u.y(), side.u.x());
  if (side.n.dot(0.5 * (side.a + b) - centroid) < 0) side.n = -side.n;  // outward
  return side;
}

// A side's edge in the frame of its first corner: offset along the outward
// normal as a quadratic in the distance along the side. Lens distortion and
// refraction at a port bend straight edges; the quadratic follows the bend
// so that the corners, extrapolated to the ends, stay unbiased on large
// markers.
struct EdgeCurve {
  Eigen::Vector2d origin, u, n;
  Eigen::Vector3d coefficients = Eigen::Vector3d::Zero();  // d(t) = c0 + c1 t + c2 t^2
  Eigen::Vector2d Point(double t) const {
    return origin + t * u + (coefficients(0) + t * (coefficients(1) + t * coefficients(2))) * n;
  }
  Eigen::Vector2d Tangent(double t) const {
    return (u + (coefficients(1) + 2 * t * coefficients(2)) * n).normalized();
  }
};

inline std::optional<Eigen::Vector2d> IntersectLines(const Eigen::Vector2d& pa,
                                                     const Eigen::Vector2d& da,
                                                     const Eigen::Vector2d& pb,
                                                     const Eigen::Vector2d& db) {
  Eigen::Matrix2d A;
  A << da, -db;
  if (std::abs(A.determinant()) < 1e-6) return std::nullopt;
  const Eigen::Vector2d t = A.colPivHouseholderQr().solve(pb - pa);
  return pa + t(0) * da;
}

// Where the end of `before` meets the start of `after`: tangent lines at
// the current estimates, intersected, a few times over.
inline std::optional<Eigen::Vector2d> IntersectCurves(const EdgeCurve& before, double before_length,
                                                      const EdgeCurve& after) {
  double t1 = before_length, t2 = 0;
  std::optional<Eigen::Vector2d> x;
  for (int iteration = 0; iteration < 5; ++iteration) {
    x = IntersectLines(before.Point(t1), before.Tangent(t1), after.Point(t2), after.Tangent(t2));
    if (!x) return std::nullopt;
    t1 = (*x - before.origin).dot(before.u);
    t2 = (*x - after.origin).dot(after.u);
  }
  return x;
}

}  // namespace portcal
