// FOV model of Devernay & Faugeras, "Straight lines have to be straight",
// MVA 2001 (COLMAP id 7): fx, fy, cx, cy, omega.
//   (ud, vd) = (u, v) * atan(2 r tan(omega / 2)) / (r omega)
// The factor has removable singularities at r = 0 and omega = 0; near them
// its Taylor series is used. Note: COLMAP 3.8's small-omega branch
// (omega^2 < 1e-4) uses the series of the *inverse* factor; portcal uses the
// series of the factor itself, so the two differ by ~omega^2/6 there.
#pragma once

#include "colmap_ext/camera/models/camera_model_base.h"

namespace portcal {

struct FOVModel : CameraModelBase<FOVModel> {
  static constexpr int kId = 7;
  static constexpr const char* kName = "FOV";
  static constexpr int kNumParams = 5;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, omega";
  static constexpr bool kSingleFocal = false;

  static void InitializeExtraParams(double* extra) { extra[0] = 1e-2; }

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    using std::atan;
    using std::sqrt;
    using std::tan;
    const T& omega = extra[0];
    const T r2 = u * u + v * v;
    const T omega2 = omega * omega;
    T factor;
    if (omega2 < T(1e-8)) {
      // a = 2 tan(w/2) = w + w^3/12 + O(w^5); factor = (a/w)(1 - a^2 r^2/3).
      factor = T(1) + omega2 / T(12) - omega2 * r2 / T(3);
    } else if (r2 < T(1e-10)) {
      const T a = T(2) * tan(omega / T(2));
      factor = a / omega * (T(1) - a * a * r2 / T(3));
    } else {
      const T r = sqrt(r2);
      factor = atan(r * T(2) * tan(omega / T(2))) / (r * omega);
    }
    *ud = u * factor;
    *vd = v * factor;
  }
};

}  // namespace portcal
