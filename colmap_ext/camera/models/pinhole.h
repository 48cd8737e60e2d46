// Pinhole models without distortion (COLMAP ids 0 and 1).
#pragma once

#include "colmap_ext/camera/models/camera_model_base.h"

namespace portcal {

// SIMPLE_PINHOLE (id 0): f, cx, cy.
struct SimplePinholeModel : CameraModelBase<SimplePinholeModel> {
  static constexpr int kId = 0;
  static constexpr const char* kName = "SIMPLE_PINHOLE";
  static constexpr int kNumParams = 3;
  static constexpr const char* kParamsInfo = "f, cx, cy";
  static constexpr bool kSingleFocal = true;

  template <typename T>
  static void Distort(const T* /*extra*/, const T& u, const T& v, T* ud, T* vd) {
    *ud = u;
    *vd = v;
  }
};

// PINHOLE (id 1): fx, fy, cx, cy.
struct PinholeModel : CameraModelBase<PinholeModel> {
  static constexpr int kId = 1;
  static constexpr const char* kName = "PINHOLE";
  static constexpr int kNumParams = 4;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy";
  static constexpr bool kSingleFocal = false;

  template <typename T>
  static void Distort(const T* /*extra*/, const T& u, const T& v, T* ud, T* vd) {
    *ud = u;
    *vd = v;
  }
};

}  // namespace portcal
