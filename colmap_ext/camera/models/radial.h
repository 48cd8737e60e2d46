// Polynomial radial distortion with one focal length (COLMAP ids 2 and 3).
//   (ud, vd) = (u, v) * (1 + k1 r^2 + k2 r^4),  r^2 = u^2 + v^2
#pragma once

#include "colmap_ext/camera/models/camera_model_base.h"

namespace portcal {

// SIMPLE_RADIAL (id 2): f, cx, cy, k.
struct SimpleRadialModel : CameraModelBase<SimpleRadialModel> {
  static constexpr int kId = 2;
  static constexpr const char* kName = "SIMPLE_RADIAL";
  static constexpr int kNumParams = 4;
  static constexpr const char* kParamsInfo = "f, cx, cy, k";
  static constexpr bool kSingleFocal = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T radial = T(1) + extra[0] * (u * u + v * v);
    *ud = u * radial;
    *vd = v * radial;
  }
};

// RADIAL (id 3): f, cx, cy, k1, k2.
struct RadialModel : CameraModelBase<RadialModel> {
  static constexpr int kId = 3;
  static constexpr const char* kName = "RADIAL";
  static constexpr int kNumParams = 5;
  static constexpr const char* kParamsInfo = "f, cx, cy, k1, k2";
  static constexpr bool kSingleFocal = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T radial = T(1) + extra[0] * r2 + extra[1] * r2 * r2;
    *ud = u * radial;
    *vd = v * radial;
  }
};

}  // namespace portcal
