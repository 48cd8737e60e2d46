#include "colmap_ext/housing/dome_port.h"

#include <algorithm>
#include <cmath>
#include <complex>

#include "colmap_ext/housing/unit_mistake.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

std::optional<std::string> DomePort::Invalidity(const double* port) {
  for (int i = 0; i < kNumParams; ++i) {
    if (!std::isfinite(port[i])) {
      return "DOMEPORT parameter " + std::to_string(i) + " is not finite";
    }
  }
  if (!(InnerRadius(port) > 0)) return "DOMEPORT int_radius must be positive";
  if (!(port[4] > 0)) return "DOMEPORT int_thick must be positive";
  // No medium has an index below vacuum's 1 (air 1.0, glass about 1.5,
  // water 1.33); a smaller one is a typo, and the solve would fail on it.
  if (!(AirIndex(port) >= 1 && GlassIndex(port) >= 1 && WaterIndex(port) >= 1)) {
    return "DOMEPORT refractive indices na, ng, nw must be at least 1 (air 1.0, glass ~1.5, water "
           "~1.33)";
  }
  const double decentering = Center(port).norm();
  if (!(decentering < InnerRadius(port))) {
    return "DOMEPORT: the camera centre must lie inside the dome, but the "
           "decentering |C| = " +
           std::to_string(decentering) +
           " m is not below int_radius = " + std::to_string(InnerRadius(port)) + " m";
  }
  return std::nullopt;
}

namespace {
constexpr double kMaxAdjustedDecentering = 0.9;  // in inner radii
}  // namespace

HousingRefinement DomePort::Refinement(const double* port) {
  HousingRefinement refinement;
  refinement.position = {0, 1, 2};
  const double bound = kMaxAdjustedDecentering * InnerRadius(port);
  for (int k = 0; k < 3; ++k) refinement.bounds.push_back({k, -bound, bound});
  refinement.position_name = "decentering";
  refinement.bound_description = "decentering 90 % of the radius";
  return refinement;
}

bool DomePort::AtBound(const double* port) {
  const double bound = kMaxAdjustedDecentering * InnerRadius(port);
  for (int k = 0; k < 3; ++k) {
    if (std::abs(port[k]) >= 0.99 * bound) return true;
  }
  return false;
}

std::vector<std::vector<double>> DomePort::StartCandidates(const double* port,
                                                           const Eigen::Vector3d& axis) {
  std::vector<std::vector<double>> starts;
  for (const Eigen::Vector3d& direction :
       {axis, Eigen::Vector3d(Eigen::Vector3d::UnitX()), Eigen::Vector3d(Eigen::Vector3d::UnitY()),
        Eigen::Vector3d(Eigen::Vector3d::UnitZ())}) {
    for (int i = -9; i <= 9; ++i) {
      std::vector<double> start(port, port + kNumParams);
      const Eigen::Vector3d centre = (0.09 * i * InnerRadius(port)) * direction;
      for (int k = 0; k < 3; ++k) start[static_cast<size_t>(k)] = centre[k];
      starts.push_back(std::move(start));
    }
  }
  return starts;
}

std::optional<std::string> DomePort::UnitMistake(const double* port) {
  if (auto mistake = LengthInMillimetres(kName, "int_radius", InnerRadius(port))) return mistake;
  if (auto mistake = LengthInMillimetres(kName, "int_thick", port[4])) return mistake;
  const char* const kCentre[3] = {"Cx", "Cy", "Cz"};
  for (int k = 0; k < 3; ++k) {
    if (auto mistake = LengthInMillimetres(kName, kCentre[k], port[k])) return mistake;
  }
  return std::nullopt;
}

std::string DomePort::InWords(const double* port) {
  // The camera frame: x right, y down, z forward (the optical axis).
  const Eigen::Vector3d c = 1000 * Center(port);
  const auto side = [](double mm, const char* positive, const char* negative) {
    return FormatFixed(std::abs(mm), 2) + " mm " + (mm >= 0 ? positive : negative);
  };
  return "the dome's centre lies " + side(c.x(), "right", "left") + ", " +
         side(c.y(), "down", "up") + " and " + side(c.z(), "ahead of", "behind") +
         " the camera's projection centre (" + FormatFixed(c.norm(), 2) + " mm off it)";
}

std::optional<std::string> DomePort::Implausibility(const double* port) {
  constexpr double kMaxPlausibleDecenteringFraction = 0.25;
  const double decentering = Center(port).norm();
  if (decentering > kMaxPlausibleDecenteringFraction * InnerRadius(port)) {
    return "the dome's centre is " + FormatFixed(1000 * decentering, 1) +
           " mm from the camera centre, " + FormatFixed(100 * decentering / InnerRadius(port), 0) +
           " % of its radius, where dome housings centre the lens to a few mm";
  }
  return std::nullopt;
}

namespace {

// The 2-D problem in the plane of refraction: camera centre O at the
// origin, dome centre C = (c, 0) on the x axis, the point X at y > 0.
//
// Both glass surfaces are spheres about C, so Bouguer's formula for
// spherically symmetric media holds across each refraction: n * h is
// conserved, h = cross(P - C, u) the signed distance of the ray from C (the
// same for every point P of a straight segment). With h = cross(O - C, d0)
// = -c sin(phi) for the air ray at angle phi:
//   glass: h_g = (na/ng) h,  water: h_w = (na/nw) h.
// The angle between a ray and the outward normal where it meets a sphere of
// radius R is asin(h / R), so following the ray through the surfaces
//   alpha1 = asin(h/R1), beta1 = asin(h_g/R1), alpha2 = asin(h_g/R2),
//   beta2 = asin(h_w/R2),  psi = phi - alpha1 + beta1 - alpha2 + beta2,
// psi the angle of the water ray. X lies on it iff
//   g(phi) = cross(X - C, u(psi)) - h_w = 0,
// a closed form with a closed-form derivative: no ray tracing inside the
// solve.
class PlaneOfRefraction {
 public:
  PlaneOfRefraction(const double* port, double center_x, const Eigen::Vector2d& point)
      : c_(center_x),
        x_(point.x() - center_x),
        y_(point.y()),
        inner_(DomePort::InnerRadius(port)),
        outer_(DomePort::OuterRadius(port)),
        glass_ratio_(DomePort::AirIndex(port) / DomePort::GlassIndex(port)),
        water_ratio_(DomePort::AirIndex(port) / DomePort::WaterIndex(port)) {}

  // g and dg/dphi; false where an asin has no real value (total internal
  // reflection). Adding asin(a) to an angle is a multiplication of its unit
  // complex number by sqrt(1 - a^2) + i a: no inverse trigonometry.
  bool Residual(double phi, double* g, double* dg) const {
    const double h = -c_ * std::sin(phi);
    const double dh = -c_ * std::cos(phi);
    std::complex<double> u = std::polar(1.0, phi);
    double dpsi = 1.0;
    // Each surface adds sign * asin(k h / R) to the direction.
    const double k[4] = {1.0, glass_ratio_, glass_ratio_, water_ratio_};
    const double radius[4] = {inner_, inner_, outer_, outer_};
    for (int i = 0; i < 4; ++i) {
      const double a = k[i] * h / radius[i];
      if (!(std::abs(a) < 1.0)) return false;
      const double sign = i % 2 == 0 ? -1.0 : 1.0;
      const double cos_a = std::sqrt(1.0 - a * a);
      u *= std::complex<double>(cos_a, sign * a);
      dpsi += sign * k[i] * dh / (radius[i] * cos_a);
      if (i == 2) exit_direction_ = u;  // direction of the exit point P2 - C
    }
    water_direction_ = u;
    *g = x_ * u.imag() - y_ * u.real() - water_ratio_ * h;
    *dg = (x_ * u.real() + y_ * u.imag()) * dpsi - water_ratio_ * dh;
    return true;
  }

  // After Residual: whether X lies in front of the water ray's start on the
  // outer sphere (not on its backward extension).
  bool PointAhead() const {
    const std::complex<double> to_point = std::complex<double>(x_, y_) - outer_ * exit_direction_;
    return to_point.real() * water_direction_.real() + to_point.imag() * water_direction_.imag() >
           0;
  }

  // Start for Newton: with asin(a) ~ a the water ray's direction is
  // psi ~ phi + kappa h = phi - kappa c sin(phi); aim it at X.
  double InitialAngle() const {
    const double kappa = (glass_ratio_ - 1.0) / inner_ + (water_ratio_ - glass_ratio_) / outer_;
    const double phi_x = std::atan2(y_, x_);
    return std::clamp(phi_x + kappa * c_ * std::sin(phi_x), 1e-9, M_PI - 1e-9);
  }

 private:
  double c_, x_, y_;  // X - C in the plane
  double inner_, outer_, glass_ratio_, water_ratio_;
  mutable std::complex<double> exit_direction_, water_direction_;
};

}  // namespace

bool DomePort::AirRayToPointValue(const double* port, const Eigen::Vector3d& point,
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
  const PlaneOfRefraction plane(port, decentering, Eigen::Vector2d(along, across));

  // Rays along the axis are not bent, so g(0) = -across < 0 and
  // g(pi) = across > 0: [0, pi] brackets a root. Safeguarded Newton.
  double lo = 0.0, hi = M_PI;
  double phi = plane.InitialAngle();
  double g = 0, dg = 0;
  bool converged = false;
  for (int iter = 0; iter < 100 && !converged; ++iter) {
    if (!plane.Residual(phi, &g, &dg)) return false;
    const double step = -g / dg;
    // Newton converges quadratically (|g''/g'| ~ 1 here): after a step
    // below 1e-7 rad the error is ~1e-14 rad, ~1e-11 px at f = 1300 px.
    converged = std::abs(step) < 1e-7;
    if (!converged) (g < 0 ? lo : hi) = phi;
    phi += step;
    if (!converged && !(phi > lo && phi < hi)) phi = 0.5 * (lo + hi);  // safeguard
  }
  if (!converged || !plane.PointAhead()) return false;
  *dir_in_air = std::cos(phi) * axis + std::sin(phi) * (perp / across);
  return true;
}

}  // namespace portcal
