// DOMEPORT (refractive COLMAP fork id 1): a spherical glass shell around the
// camera. Parameters, in this order:
//   Cx, Cy, Cz   centre of the sphere in the camera frame (m): the decentering
//   int_radius   inner radius (m); the outer radius is int_radius + int_thick
//   int_thick    glass thickness (m)
//   na, ng, nw   refractive indices of air, glass and water
// The camera centre must lie inside the inner sphere. A perfectly centred dome
// does not refract rays through the camera centre. She et al., "Adjustment
// and calibration of dome port camera systems for underwater vision", GCPR
// 2019.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "colmap_ext/housing/housing_refinement.h"
#include "colmap_ext/housing/refraction.h"

namespace portcal {

struct DomePort {
  static constexpr int kId = 1;
  static constexpr const char* kName = "DOMEPORT";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "Cx, Cy, Cz, int_radius, int_thick, na, ng, nw";

  template <typename T>
  static VectorT<T, 3> Center(const T* port) {
    return {port[0], port[1], port[2]};
  }
  // The unit axis every plane of refraction contains, through the camera
  // centre and the dome's; false for a concentric dome, whose rays through
  // the centre are not bent.
  template <typename T>
  [[nodiscard]] static bool RefractionAxis(const T* port, VectorT<T, 3>* axis) {
    const VectorT<T, 3> center = Center(port);
    if (!(center.norm() > T(1e-12))) return false;
    *axis = center.normalized();
    return true;
  }
  template <typename T>
  static const T& InnerRadius(const T* port) {
    return port[3];
  }
  template <typename T>
  static T OuterRadius(const T* port) {
    return port[3] + port[4];
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

  static std::optional<std::string> Invalidity(const double* port);

  // Why a real housing would hardly have these (valid) parameters, or
  // nullopt: a camera centre decentred by more than a quarter of the inner
  // radius. Dome housings are built to centre the lens's entrance pupil to
  // a few mm; beyond, the refraction is strong enough that a real lens
  // would show it and a self-calibration that ends there has likely traded
  // the dome against the focal length.
  static std::optional<std::string> Implausibility(const double* port);
  // A length given in millimetres where portcal takes metres (a radius,
  // thickness or decentering of a metre or more), or nullopt.
  static std::optional<std::string> UnitMistake(const double* port);
  // Where the dome sits, in words a housing drawing is checked against:
  // its centre right/left, down/up and ahead of/behind the camera's
  // projection centre, in millimetres.
  static std::string InWords(const double* port);

  // An adjustment refines the centre, each coordinate within 90 % of the
  // inner radius: the camera centre stays inside the dome.
  static HousingRefinement Refinement(const double* port);
  // A centre coordinate at its bound: the adjustment traded it.
  static bool AtBound(const double* port);
  // Starts for a housing calibration given the refraction axis the views
  // show: decenterings of up to 81 % of the inner radius along that axis
  // and, because a nearly central dome shows its axis poorly, along the
  // camera's own axes; the radius and constants from `port`.
  static std::vector<std::vector<double>> StartCandidates(const double* port,
                                                          const Eigen::Vector3d& axis);
  // Centred, a dome does not magnify paraxial rays; decentring's effect is
  // left to the adjustment.
  static double InAirFocalRatio(const double* /*port*/) { return 1.0; }

  // Traces a ray from `origin` (inside the inner sphere) along `dir_in_air`
  // through both spheres. Templated on the dimension so the forward solve can
  // run it inside the 2-D plane of refraction.
  template <typename T, int Dim>
  [[nodiscard]] static bool Trace(const VectorT<T, Dim>& center, const T* port,
                                  const VectorT<T, Dim>& origin, const VectorT<T, Dim>& dir_in_air,
                                  VectorT<T, Dim>* water_origin, VectorT<T, Dim>* water_dir) {
    const VectorT<T, Dim> d0 = dir_in_air.normalized();
    T s0;
    if (!ExitDistanceFromInside<T, Dim>(origin, d0, center, InnerRadius(port), &s0)) {
      return false;
    }
    const VectorT<T, Dim> p1 = origin + s0 * d0;
    VectorT<T, Dim> d1;
    if (!Refract<T, Dim>(d0, (p1 - center) / InnerRadius(port), AirIndex(port) / GlassIndex(port),
                         &d1)) {
      return false;
    }
    T s1;
    if (!ExitDistanceFromInside<T, Dim>(p1, d1, center, OuterRadius(port), &s1)) {
      return false;
    }
    *water_origin = p1 + s1 * d1;
    return Refract<T, Dim>(d1, (*water_origin - center) / OuterRadius(port),
                           GlassIndex(port) / WaterIndex(port), water_dir);
  }

  // Back-projection: ray from the camera centre along `dir_in_air` -> ray in
  // water (origin on the outer sphere, unit direction). False on total
  // internal reflection at the glass-water surface.
  template <typename T>
  [[nodiscard]] static bool RayInWater(const T* port, const VectorT<T, 3>& dir_in_air,
                                       VectorT<T, 3>* origin, VectorT<T, 3>* dir) {
    return Trace<T, 3>(Center(port), port, VectorT<T, 3>::Zero(), dir_in_air, origin, dir);
  }

  // Forward projection, exact: unit air direction of the ray that reaches
  // `point` (camera frame, outside the outer sphere). The ray lies in the
  // plane through the camera centre, C and the point. There, because both
  // surfaces are spheres about C, Bouguer's invariant n * (signed distance of
  // the ray from C) gives the water ray of the air angle phi in closed form,
  // and phi solves a 1-D equation by safeguarded Newton with its analytic
  // derivative (see dome_port.cc). False if no ray reaches the point.
  static bool AirRayToPointValue(const double* port, const Eigen::Vector3d& point,
                                 Eigen::Vector3d* dir_in_air);
};

}  // namespace portcal
