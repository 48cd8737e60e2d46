// FLATPORT (refractive COLMAP fork id 0): a glass plate of thickness int_thick
// in front of the camera. Parameters, in this order:
//   Nx, Ny, Nz   unit normal of the interface in the camera frame, pointing
//                into the water
//   int_dist     distance (m) of the inner, air-glass surface from the camera
//                centre: the surface is the plane n . X = int_dist
//   int_thick    glass thickness (m): the outer surface is n . X = int_dist +
//                int_thick
//   na, ng, nw   refractive indices of air, glass and water
// Treibitz et al., PAMI 2012; Agrawal et al., "A theory of multi-layer flat
// refractive geometry", CVPR 2012.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "colmap_ext/housing/housing_refinement.h"
#include "colmap_ext/housing/refraction.h"
#include "colmap_ext/util/jet_utils.h"

namespace portcal {

struct FlatPort {
  static constexpr int kId = 0;
  static constexpr const char* kName = "FLATPORT";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "Nx, Ny, Nz, int_dist, int_thick, na, ng, nw";

  // Normalized, so that derivatives w.r.t. (Nx, Ny, Nz) are those of the
  // direction (the stored vector is unit up to rounding; Invalidity checks).
  template <typename T>
  static VectorT<T, 3> Normal(const T* port) {
    return VectorT<T, 3>(port[0], port[1], port[2]).normalized();
  }
  template <typename T>
  static const T& InterfaceDistance(const T* port) {
    return port[3];
  }
  template <typename T>
  static const T& Thickness(const T* port) {
    return port[4];
  }
  template <typename T>
  static const T& AirIndex(const T* port) {
    return port[5];
  }
  template <typename T>
  static const T& GlassIndex(const T* port) {
    return port[6];
  }
  template <typename T>
  static const T& WaterIndex(const T* port) {
    return port[7];
  }

  // The unit axis every plane of refraction contains, through the camera
  // centre: the normal (always there).
  template <typename T>
  [[nodiscard]] static bool RefractionAxis(const T* port, VectorT<T, 3>* axis) {
    *axis = Normal(port);
    return true;
  }

  // Why these parameters describe no flat port, or nullopt if they do.
  static std::optional<std::string> Invalidity(const double* port);

  // Why a real housing would hardly have these (valid) parameters, or
  // nullopt: a camera centre more than 10 cm behind the port, or a port
  // tilted more than 10 deg from the optical axis. Housings put the lens
  // within a few cm of a port mounted square to it; a self-calibration
  // that ends beyond has traded the port against the lens (issue 21: 14 deg
  // and 0.1 mm, 11.4 deg and 361 mm).
  static std::optional<std::string> Implausibility(const double* port);
  // A length given in millimetres where portcal takes metres (a distance
  // or thickness of a metre or more), or nullopt.
  static std::optional<std::string> UnitMistake(const double* port);
  // Where the port sits, in words a housing drawing is checked against: the
  // tilt of its normal from the optical axis and towards which side, and
  // the inner surface's distance from the projection centre.
  static std::string InWords(const double* port);

  // An adjustment refines the normal (on the sphere) and the distance, down
  // to 0.1 mm: the interface is in front of the lens, and a distance the
  // data cannot fix must not wander through zero.
  static HousingRefinement Refinement(const double* port);
  // The distance at its floor: the adjustment traded it, not measured it.
  static bool AtBound(const double* port);
  // Starts for a housing calibration given the refraction axis the views
  // show (up to sign): that normal, facing forward, at distances from 1 mm
  // to 15 cm on a log grid; the constants from `port`.
  static std::vector<std::vector<double>> StartCandidates(const double* port,
                                                          const Eigen::Vector3d& axis);
  // In-air focal length over the one the camera appears to have behind the
  // port near the axis: a flat port magnifies paraxial rays by nw / na
  // (tan a_air = nw / na tan a_water).
  static double InAirFocalRatio(const double* port) { return AirIndex(port) / WaterIndex(port); }

  // Back-projection: a ray leaving the camera centre along `dir_in_air` (any
  // length) -> ray in water, origin on the outer surface, unit direction.
  // False if the ray misses the port (n . d <= 0) or is totally reflected.
  template <typename T>
  [[nodiscard]] static bool RayInWater(const T* port, const VectorT<T, 3>& dir_in_air,
                                       VectorT<T, 3>* origin, VectorT<T, 3>* dir) {
    const VectorT<T, 3> n = Normal(port);
    const VectorT<T, 3> d0 = dir_in_air.normalized();
    const T cos0 = n.dot(d0);
    if (!(cos0 > T(0))) return false;
    const VectorT<T, 3> p1 = (InterfaceDistance(port) / cos0) * d0;
    VectorT<T, 3> d1;
    if (!Refract<T, 3>(d0, n, AirIndex(port) / GlassIndex(port), &d1)) {
      return false;
    }
    *origin = p1 + (Thickness(port) / n.dot(d1)) * d1;
    return Refract<T, 3>(d1, n, GlassIndex(port) / WaterIndex(port), dir);
  }

  // Forward projection, exact: the unit direction in air, from the camera
  // centre, of the ray that reaches `point` (camera frame, in water). The ray
  // stays in the plane spanned by n and the point; there the sine s of the
  // air angle solves the 1-D equation (radial distance as a sum over layers)
  //   d s / ca + t ra s / cg + w rw s / cw = r,
  //   ra = na/ng, rw = na/nw, cg = sqrt(1 - ra^2 s^2), ...
  // whose left side is convex and increasing in s, so a safeguarded Newton
  // iteration with the analytic derivative converges from any start.
  // False if the point is not beyond the outer surface.
  static bool AirRayToPointValue(const double* port, const Eigen::Vector3d& point,
                                 Eigen::Vector3d* dir_in_air);
};

}  // namespace portcal
