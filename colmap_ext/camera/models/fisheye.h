// Fisheye models built on the equidistant angle theta = atan(r) (COLMAP ids
// 5, 8, 9, 10). OPENCV_FISHEYE equals cv::fisheye::projectPoints.
//   (ud, vd) = (u, v) * theta_d / r,  theta_d = theta (1 + k1 theta^2 + ...)
// theta/r and theta^2 are computed from r^2 (AtanROverR) so the models and
// their derivatives stay finite on the optical axis.
#pragma once

#include "colmap_ext/camera/models/camera_model_base.h"
#include "colmap_ext/camera/models/opencv.h"

namespace portcal {

// OPENCV_FISHEYE (id 5): fx, fy, cx, cy, k1, k2, k3, k4.
struct OpenCVFisheyeModel : CameraModelBase<OpenCVFisheyeModel> {
  static constexpr int kId = 5;
  static constexpr const char* kName = "OPENCV_FISHEYE";
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, k3, k4";
  static constexpr bool kSingleFocal = false;
  static constexpr bool kFisheye = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T theta_over_r = AtanROverR(r2);
    const T t2 = r2 * theta_over_r * theta_over_r;
    const T poly = T(1) + t2 * (extra[0] + t2 * (extra[1] + t2 * (extra[2] + t2 * extra[3])));
    const T scale = theta_over_r * poly;
    *ud = u * scale;
    *vd = v * scale;
  }
};

// SIMPLE_RADIAL_FISHEYE (id 8): f, cx, cy, k.
struct SimpleRadialFisheyeModel : CameraModelBase<SimpleRadialFisheyeModel> {
  static constexpr int kId = 8;
  static constexpr const char* kName = "SIMPLE_RADIAL_FISHEYE";
  static constexpr int kNumParams = 4;
  static constexpr const char* kParamsInfo = "f, cx, cy, k";
  static constexpr bool kSingleFocal = true;
  static constexpr bool kFisheye = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T theta_over_r = AtanROverR(r2);
    const T t2 = r2 * theta_over_r * theta_over_r;
    const T scale = theta_over_r * (T(1) + extra[0] * t2);
    *ud = u * scale;
    *vd = v * scale;
  }
};

// RADIAL_FISHEYE (id 9): f, cx, cy, k1, k2.
struct RadialFisheyeModel : CameraModelBase<RadialFisheyeModel> {
  static constexpr int kId = 9;
  static constexpr const char* kName = "RADIAL_FISHEYE";
  static constexpr int kNumParams = 5;
  static constexpr const char* kParamsInfo = "f, cx, cy, k1, k2";
  static constexpr bool kSingleFocal = true;
  static constexpr bool kFisheye = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T r2 = u * u + v * v;
    const T theta_over_r = AtanROverR(r2);
    const T t2 = r2 * theta_over_r * theta_over_r;
    const T scale = theta_over_r * (T(1) + t2 * (extra[0] + t2 * extra[1]));
    *ud = u * scale;
    *vd = v * scale;
  }
};

// THIN_PRISM_FISHEYE (id 10): fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1,
// sy1. The equidistant mapping first, then radial (k1..k4 on r^2..r^8 of the
// mapped point), tangential (p1, p2) and thin-prism (sx1, sy1) terms.
struct ThinPrismFisheyeModel : CameraModelBase<ThinPrismFisheyeModel> {
  static constexpr int kId = 10;
  static constexpr const char* kName = "THIN_PRISM_FISHEYE";
  static constexpr int kNumParams = 12;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1";
  static constexpr bool kSingleFocal = false;
  static constexpr bool kFisheye = true;

  template <typename T>
  static void Distort(const T* extra, const T& u, const T& v, T* ud, T* vd) {
    const T theta_over_r = AtanROverR(u * u + v * v);
    const T uu = u * theta_over_r;
    const T vv = v * theta_over_r;
    const T r2 = uu * uu + vv * vv;
    const T radial = T(1) + r2 * (extra[0] + r2 * (extra[1] + r2 * (extra[4] + r2 * extra[5])));
    *ud = uu * radial + extra[6] * r2;
    *vd = vv * radial + extra[7] * r2;
    AddTangentialDistortion(extra[2], extra[3], uu, vv, ud, vd);
  }
};

}  // namespace portcal
