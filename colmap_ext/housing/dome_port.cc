#include "colmap_ext/housing/dome_port.h"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>

namespace portcal {

std::optional<std::string> DomePort::Invalidity(const double* port) {
  for (int i = 0; i < kNumParams; ++i) {
    if (!std::isfinite(port[i])) {
      return "DOMEPORT parameter " + std::to_string(i) + " is not finite";
    }
  }
  if (!(InnerRadius(port) > 0)) return "DOMEPORT int_radius must be positive";
  if (!(port[4] > 0)) return "DOMEPORT int_thick must be positive";
  if (!(AirIndex(port) > 0 && GlassIndex(port) > 0 && WaterIndex(port) > 0)) {
    return "DOMEPORT refractive indices must be positive";
  }
  const double decentering = Center(port).norm();
  if (!(decentering < InnerRadius(port))) {
    return "DOMEPORT: the camera centre must lie inside the dome, but the "
           "decentering |C| = " + std::to_string(decentering) +
           " m is not below int_radius = " + std::to_string(InnerRadius(port)) +
           " m";
  }
  return std::nullopt;
}

namespace {

using Jet1 = ceres::Jet<double, 1>;

// g(phi) = cross(water_dir, point - water_origin) in the plane of refraction
// (axis along x, the point at y > 0), with dg/dphi in g.v[0].
bool PlaneResidual(const double* port, double center_x,
                   const Eigen::Vector2d& point, double phi, Jet1* g) {
  Jet1 port_jet[DomePort::kNumParams];
  for (int i = 0; i < DomePort::kNumParams; ++i) port_jet[i] = Jet1(port[i]);
  const Jet1 angle(phi, 0);
  const VectorT<Jet1, 2> dir(cos(angle), sin(angle));
  const VectorT<Jet1, 2> center(Jet1(center_x), Jet1(0.0));
  VectorT<Jet1, 2> water_origin, water_dir;
  if (!DomePort::Trace<Jet1, 2>(center, port_jet, VectorT<Jet1, 2>::Zero(),
                                dir, &water_origin, &water_dir)) {
    return false;
  }
  const VectorT<Jet1, 2> q = point.cast<Jet1>() - water_origin;
  *g = water_dir.x() * q.y() - water_dir.y() * q.x();
  return true;
}

}  // namespace

bool DomePort::AirRayToPointValue(const double* port,
                                  const Eigen::Vector3d& point,
                                  Eigen::Vector3d* dir_in_air) {
  const Eigen::Vector3d center = Center(port);
  if (!((point - center).norm() > OuterRadius(port))) return false;
  const double decentering = center.norm();
  if (decentering <= 1e-14 * InnerRadius(port)) {  // concentric: no bending
    *dir_in_air = point.normalized();
    return true;
  }
  const Eigen::Vector3d axis = center / decentering;
  const double along = axis.dot(point);
  const Eigen::Vector3d perp = point - along * axis;
  const double across = perp.norm();
  if (across <= 1e-15 * point.norm()) {  // on the axis: not bent
    *dir_in_air = along > 0 ? axis : Eigen::Vector3d(-axis);
    return true;
  }
  const Eigen::Vector2d point_2d(along, across);

  // g > 0 for rays left of the solution (phi smaller), g < 0 right of it
  // (g(0) = across > 0, g(pi) = -across < 0). Bracket around the direct
  // direction, widening geometrically.
  const double phi0 = std::atan2(across, along);
  double lo = phi0, hi = phi0;
  Jet1 g;
  double step = 1e-3;
  for (bool found = false; !found;) {
    lo = std::max(0.0, lo - step);
    hi = std::min(M_PI, hi + step);
    Jet1 g_lo, g_hi;
    if (!PlaneResidual(port, decentering, point_2d, lo, &g_lo) ||
        !PlaneResidual(port, decentering, point_2d, hi, &g_hi)) {
      return false;
    }
    found = g_lo.a >= 0 && g_hi.a <= 0;
    if (!found && lo == 0.0 && hi == M_PI) return false;
    step *= 2;
  }

  double phi = std::clamp(phi0, lo, hi);
  for (int iter = 0; iter < 100; ++iter) {
    if (!PlaneResidual(port, decentering, point_2d, phi, &g)) return false;
    if (g.a == 0.0) break;
    (g.a > 0 ? lo : hi) = phi;
    double next = phi - g.a / g.v[0];
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // safeguard
    const bool converged = std::abs(next - phi) <= 1e-16 * std::max(1.0, phi);
    phi = next;
    if (converged || hi - lo <= 1e-16) break;
  }
  *dir_in_air = std::cos(phi) * axis + std::sin(phi) * (perp / across);
  // The point must lie ahead on the water ray, not on its backward extension.
  Eigen::Vector3d water_origin, water_dir;
  if (!RayInWater<double>(port, *dir_in_air, &water_origin, &water_dir)) {
    return false;
  }
  return water_dir.dot(point - water_origin) > 0;
}

}  // namespace portcal
