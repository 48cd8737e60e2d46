// The shape every COLMAP camera model shares: focal length(s), principal point
// and a lens distortion acting on normalized image coordinates.
//
//   pixel = (fx * ud + cx, fy * vd + cy),   (ud, vd) = Distort(u / w, v / w)
//
// Each model is a stateless struct deriving from CameraModelBase<Model> and
// providing `Distort` (normalized -> distorted normalized coordinates) as a
// template so Ceres autodiff runs through it. Pixels follow COLMAP: the centre
// of the top-left pixel is (0.5, 0.5).
#pragma once

#include <ceres/jet.h>

#include <cmath>
#include <vector>

#include "colmap_ext/util/jet_utils.h"

namespace portcal {

// atan(r) / r as a function of r^2, smooth (and Jet-differentiable) at r = 0.
// Below r^2 = 1e-8 the Taylor series 1 - r^2/3 + r^4/5 is exact to 1e-25.
template <typename T>
T AtanROverR(const T& r2) {
  using std::atan;
  using std::sqrt;
  if (r2 < T(1e-8)) return T(1) - r2 / T(3) + r2 * r2 / T(5);
  const T r = sqrt(r2);
  return atan(r) / r;
}

struct UndistortionOptions {
  // Newton stops when the step is below this (normalized units): 1e-14 is
  // ~1e-11 px at f = 1000.
  double step_tolerance = 1e-14;
  int max_num_iterations = 100;
};

template <typename Model>
struct CameraModelBase {
  // Built on the equidistant angle (fisheye.h): with its distortion at 0 the
  // model is the equidistant projection, not the pinhole.
  static constexpr bool kFisheye = false;

  // Single-focal models store (f, cx, cy, extra...), the others
  // (fx, fy, cx, cy, extra...).
  static constexpr int FocalCount() { return Model::kSingleFocal ? 1 : 2; }
  static constexpr int ExtraOffset() { return FocalCount() + 2; }
  static constexpr int NumExtraParams() { return Model::kNumParams - ExtraOffset(); }

  static std::vector<int> FocalLengthIdxs() {
    return Model::kSingleFocal ? std::vector<int>{0} : std::vector<int>{0, 1};
  }
  static std::vector<int> PrincipalPointIdxs() {
    return Model::kSingleFocal ? std::vector<int>{1, 2} : std::vector<int>{2, 3};
  }
  static std::vector<int> ExtraParamsIdxs() {
    std::vector<int> idxs;
    for (int i = ExtraOffset(); i < Model::kNumParams; ++i) idxs.push_back(i);
    return idxs;
  }

  // COLMAP's default initialisation: focal, image centre, zero distortion.
  static std::vector<double> InitializeParams(double focal_length, int width, int height) {
    std::vector<double> params(Model::kNumParams, 0.0);
    params[0] = focal_length;
    if (!Model::kSingleFocal) params[1] = focal_length;
    params[FocalCount()] = width / 2.0;
    params[FocalCount() + 1] = height / 2.0;
    Model::InitializeExtraParams(params.data() + ExtraOffset());
    return params;
  }
  static void InitializeExtraParams(double* /*extra*/) {}

  template <typename T>
  static T Fx(const T* params) {
    return params[0];
  }
  template <typename T>
  static T Fy(const T* params) {
    return params[Model::kSingleFocal ? 0 : 1];
  }
  template <typename T>
  static T Cx(const T* params) {
    return params[FocalCount()];
  }
  template <typename T>
  static T Cy(const T* params) {
    return params[FocalCount() + 1];
  }

  // Point in the camera frame -> pixel. False if the point is not in front of
  // the camera (w <= 0); outputs are then untouched.
  template <typename T>
  [[nodiscard]] static bool ImgFromCam(const T* params, const T& u, const T& v, const T& w, T* x,
                                       T* y) {
    if (!(w > T(0))) return false;
    T ud, vd;
    Model::Distort(params + ExtraOffset(), u / w, v / w, &ud, &vd);
    *x = Fx(params) * ud + Cx(params);
    *y = Fy(params) * vd + Cy(params);
    return true;
  }

  // Pixel -> normalized ray (u, v, 1) in the camera frame, inverting Distort
  // by Newton's method with its exact (autodiff) Jacobian. For Jets the
  // solution is found on the values and one Newton step in T then carries the
  // exact first derivatives (implicit function theorem: du/dp = -J^-1 dr/dp).
  // False if Newton does not converge (pixel outside the lens' valid region).
  template <typename T>
  [[nodiscard]] static bool CamFromImg(const T* params, const T& x, const T& y, T* u, T* v,
                                       const UndistortionOptions& options = {}) {
    const T xd = (x - Cx(params)) / Fx(params);
    const T yd = (y - Cy(params)) / Fy(params);
    double extra[Model::kNumParams];
    for (int i = 0; i < NumExtraParams(); ++i) {
      extra[i] = ScalarPart(params[ExtraOffset() + i]);
    }
    double u0 = ScalarPart(xd);
    double v0 = ScalarPart(yd);
    double jacobian[4];
    if (!UndistortValues(extra, ScalarPart(xd), ScalarPart(yd), options, &u0, &v0, jacobian)) {
      return false;
    }
    if constexpr (std::is_same_v<T, double>) {
      *u = u0;
      *v = v0;
    } else {
      // One Newton step in T from the converged values.
      T ud, vd;
      Model::Distort(params + ExtraOffset(), T(u0), T(v0), &ud, &vd);
      const T ru = ud - xd;
      const T rv = vd - yd;
      const double det = jacobian[0] * jacobian[3] - jacobian[1] * jacobian[2];
      *u = T(u0) - (jacobian[3] * ru - jacobian[1] * rv) / det;
      *v = T(v0) - (-jacobian[2] * ru + jacobian[0] * rv) / det;
    }
    return true;
  }

  // Newton on Distort(u, v) = (xd, yd) in doubles. jacobian (row-major 2x2)
  // is d Distort / d(u, v) at the solution.
  static bool UndistortValues(const double* extra, double xd, double yd,
                              const UndistortionOptions& options, double* u, double* v,
                              double* jacobian) {
    using Jet2 = ceres::Jet<double, 2>;
    Jet2 extra_jet[Model::kNumParams];
    for (int i = 0; i < NumExtraParams(); ++i) extra_jet[i] = Jet2(extra[i]);
    double uu = xd, vv = yd;
    for (int iter = 0; iter < options.max_num_iterations; ++iter) {
      Jet2 ud, vd;
      Model::Distort(extra_jet, Jet2(uu, 0), Jet2(vv, 1), &ud, &vd);
      jacobian[0] = ud.v[0];
      jacobian[1] = ud.v[1];
      jacobian[2] = vd.v[0];
      jacobian[3] = vd.v[1];
      const double ru = ud.a - xd;
      const double rv = vd.a - yd;
      const double det = jacobian[0] * jacobian[3] - jacobian[1] * jacobian[2];
      if (!std::isfinite(det) || std::abs(det) < 1e-12) return false;
      const double du = (jacobian[3] * ru - jacobian[1] * rv) / det;
      const double dv = (-jacobian[2] * ru + jacobian[0] * rv) / det;
      uu -= du;
      vv -= dv;
      if (!std::isfinite(uu) || !std::isfinite(vv)) return false;
      if (std::abs(du) + std::abs(dv) <
          options.step_tolerance * (1.0 + std::abs(uu) + std::abs(vv))) {
        *u = uu;
        *v = vv;
        // Refresh the Jacobian at the returned point.
        Jet2 ju, jv;
        Model::Distort(extra_jet, Jet2(uu, 0), Jet2(vv, 1), &ju, &jv);
        jacobian[0] = ju.v[0];
        jacobian[1] = ju.v[1];
        jacobian[2] = jv.v[0];
        jacobian[3] = jv.v[1];
        return true;
      }
    }
    return false;
  }
};

}  // namespace portcal
