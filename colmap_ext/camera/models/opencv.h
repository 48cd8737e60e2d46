// OpenCV's Brown-Conrady models (COLMAP ids 4 and 6), identical to
// cv::projectPoints with the same coefficients (pixels shifted by 0.5: OpenCV
// puts the centre of the top-left pixel at (0, 0)).
#pragma once

#include "colmap_ext/camera/models/camera_model_base.h"

namespace portcal {

// Tangential (decentering) terms shared by both models.
template <typename T>
void AddTangentialDistortion(const T& p1, const T& p2, const T& u, const T& v, T* ud, T* vd) {
  const T r2 = u * u + v * v;
  *ud += T(2) * p1 * u * v + p2 * (r2 + T(2) * u * u);
  *vd += T(2) * p2 * u * v + p1 * (r2 + T(2) * v * v);
}

// OPENCV (id 4): fx, fy, cx, cy, k1, k2, p1, p2.
struct OpenCVModel : CameraModelBase<OpenCVModel> {
  static constexpr int kId = 4;
  static constexpr const char* kName = "OPENCV";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2";
  static constexpr bool kSingleFocal = false;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T radial = T(1) + extra[0] * r2 + extra[1] * r2 * r2;
    *ud = u * radial;
    *vd = v * radial;
    AddTangentialDistortion(extra[2], extra[3], u, v, ud, vd);
  }
};

// FULL_OPENCV (id 6): fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6.
// Rational radial term (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + ...).
struct FullOpenCVModel : CameraModelBase<FullOpenCVModel> {
  static constexpr int kId = 6;
  static constexpr const char* kName = "FULL_OPENCV";
  static constexpr int kNumParams = 12;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6";
  static constexpr bool kSingleFocal = false;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T r4 = r2 * r2;
    const T r6 = r4 * r2;
    const T radial = (T(1) + extra[0] * r2 + extra[1] * r4 + extra[4] * r6) /
                     (T(1) + extra[5] * r2 + extra[6] * r4 + extra[7] * r6);
    *ud = u * radial;
    *vd = v * radial;
    AddTangentialDistortion(extra[2], extra[3], u, v, ud, vd);
  }
};

}  // namespace portcal
