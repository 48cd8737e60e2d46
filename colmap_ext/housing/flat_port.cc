#include "colmap_ext/housing/flat_port.h"

#include <algorithm>
#include <cmath>

#include "colmap_ext/housing/unit_mistake.h"
#include "colmap_ext/util/string_utils.h"

namespace portcal {

std::optional<std::string> FlatPort::Invalidity(const double* port) {
  for (int i = 0; i < kNumParams; ++i) {
    if (!std::isfinite(port[i])) {
      return "FLATPORT parameter " + std::to_string(i) + " is not finite";
    }
  }
  const double norm = Eigen::Vector3d(port[0], port[1], port[2]).norm();
  if (std::abs(norm - 1.0) > 1e-6) {
    return "FLATPORT normal (Nx, Ny, Nz) must be a unit vector, its norm is " +
           std::to_string(norm);
  }
  if (port[2] <= 0) {
    return "FLATPORT normal must point forward, into the water (Nz > 0)";
  }
  if (!(InterfaceDistance(port) > 0)) {
    return "FLATPORT int_dist must be positive";
  }
  if (!(Thickness(port) > 0)) return "FLATPORT int_thick must be positive";
  // No medium has an index below vacuum's 1 (air 1.0, glass about 1.5,
  // water 1.33); a smaller one is a typo, and the solve would fail on it.
  if (!(AirIndex(port) >= 1 && GlassIndex(port) >= 1 && WaterIndex(port) >= 1)) {
    return "FLATPORT refractive indices na, ng, nw must be at least 1 (air 1.0, glass ~1.5, water "
           "~1.33)";
  }
  return std::nullopt;
}

std::optional<std::string> FlatPort::UnitMistake(const double* port) {
  if (auto mistake = LengthInMillimetres(kName, "int_dist", InterfaceDistance(port)))
    return mistake;
  return LengthInMillimetres(kName, "int_thick", Thickness(port));
}

std::string FlatPort::InWords(const double* port) {
  const Eigen::Vector3d n = Normal(port);
  const double tilt_deg = std::acos(std::clamp(n.z(), -1.0, 1.0)) * 180.0 / M_PI;
  // The camera frame: x right, y down, z forward (the optical axis).
  const double right_deg = std::atan2(n.x(), n.z()) * 180.0 / M_PI;
  const double down_deg = std::atan2(n.y(), n.z()) * 180.0 / M_PI;
  return "the port's normal is tilted " + FormatFixed(tilt_deg, 2) +
         " deg from the optical axis (" + FormatFixed(std::abs(right_deg), 2) +
         " deg towards the image's " + (right_deg >= 0 ? "right" : "left") + ", " +
         FormatFixed(std::abs(down_deg), 2) + " deg towards its " +
         (down_deg >= 0 ? "bottom" : "top") + "); its inner surface is " +
         FormatFixed(1000 * InterfaceDistance(port), 2) +
         " mm in front of the camera's projection centre";
}

std::optional<std::string> FlatPort::Implausibility(const double* port) {
  constexpr double kMaxPlausibleDistance = 0.1;
  constexpr double kMaxPlausibleTiltDeg = 10.0;
  const double distance = InterfaceDistance(port);
  if (distance > kMaxPlausibleDistance) {
    return "the flat port's inner surface is " + FormatFixed(1000 * distance, 1) +
           " mm in front of the camera centre, where housings put it within a few cm";
  }
  const Eigen::Vector3d normal(port[0], port[1], port[2]);
  const double tilt_deg = std::acos(std::min(1.0, normal.normalized().z())) * 180.0 / M_PI;
  if (tilt_deg > kMaxPlausibleTiltDeg) {
    return "the flat port is tilted " + FormatFixed(tilt_deg, 1) +
           " deg from the optical axis, where housings mount it within a few degrees of square";
  }
  return std::nullopt;
}

namespace {
constexpr double kMinAdjustedDistance = 1e-4;  // metres
}  // namespace

HousingRefinement FlatPort::Refinement(const double* /*port*/) {
  HousingRefinement refinement;
  refinement.orientation = {0, 1, 2};
  refinement.position = {3};
  refinement.bounds = {{3, kMinAdjustedDistance}};
  refinement.position_name = "port distance";
  refinement.bound_description = "port distance 0.1 mm";
  return refinement;
}

bool FlatPort::AtBound(const double* port) {
  return InterfaceDistance(port) <= 1.5 * kMinAdjustedDistance;
}

std::vector<std::vector<double>> FlatPort::StartCandidates(const double* port,
                                                           const Eigen::Vector3d& axis) {
  const Eigen::Vector3d normal = axis.z() < 0 ? Eigen::Vector3d(-axis) : axis;
  std::vector<std::vector<double>> starts;
  for (int i = 0; i < 15; ++i) {
    std::vector<double> start(port, port + kNumParams);
    for (int k = 0; k < 3; ++k) start[static_cast<size_t>(k)] = normal[k];
    start[3] = 1e-3 * std::pow(150.0, i / 14.0);
    starts.push_back(std::move(start));
  }
  return starts;
}

bool FlatPort::AirRayToPointValue(const double* port, const Eigen::Vector3d& point,
                                  Eigen::Vector3d* dir_in_air) {
  const Eigen::Vector3d n = Normal(port);
  const double d = InterfaceDistance(port);
  const double t = Thickness(port);
  const double z = n.dot(point);
  const double w = z - d - t;  // depth of the point beyond the outer surface
  if (!(w > 0)) return false;
  const Eigen::Vector3d radial = point - z * n;
  const double r = radial.norm();
  if (r <= 1e-15 * z) {  // on the axis: the ray is not bent
    *dir_in_air = n;
    return true;
  }
  const double ra = AirIndex(port) / GlassIndex(port);
  const double rw = AirIndex(port) / WaterIndex(port);
  // The air sine s is limited to where every layer still transmits.
  double s_max = 1.0;
  if (ra > 1.0) s_max = std::min(s_max, 1.0 / ra);
  if (rw > 1.0) s_max = std::min(s_max, 1.0 / rw);

  // Radial distance reached at depth z by the ray of air sine s, minus r, and
  // its derivative: d/ds [k s / sqrt(1 - k^2 s^2)] = k / (1 - k^2 s^2)^1.5.
  const auto residual = [&](double s, double* derivative) {
    const double ca2 = 1.0 - s * s;
    const double cg2 = 1.0 - ra * ra * s * s;
    const double cw2 = 1.0 - rw * rw * s * s;
    const double ca = std::sqrt(ca2), cg = std::sqrt(cg2), cw = std::sqrt(cw2);
    *derivative = d / (ca2 * ca) + t * ra / (cg2 * cg) + w * rw / (cw2 * cw);
    return d * s / ca + t * ra * s / cg + w * rw * s / cw - r;
  };

  double lo = 0.0, hi = s_max;
  double s = std::clamp(r / point.norm(), 0.0, s_max);
  if (s <= lo || s >= hi) s = 0.5 * (lo + hi);
  for (int iter = 0; iter < 200; ++iter) {
    double derivative;
    const double value = residual(s, &derivative);
    const double step = -value / derivative;
    // A step below 1e-15 in the sine (~1e-12 px at f = 1300 px) is rounding
    // noise: done, before the bracket logic could turn it into bisection.
    if (!(std::abs(step) > 1e-15)) break;
    (value < 0 ? lo : hi) = s;
    s += step;
    if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);  // safeguard
  }
  if (!std::isfinite(s)) return false;
  *dir_in_air = std::sqrt(1.0 - s * s) * n + (s / r) * radial;
  return true;
}

}  // namespace portcal
