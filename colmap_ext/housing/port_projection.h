// Projection through camera + port, templated on both models and on the
// scalar, so Ceres autodiff runs through the exact refraction.
#pragma once

#include <ceres/jet.h>

#include <type_traits>

#include "colmap_ext/housing/refraction.h"
#include "colmap_ext/util/jet_utils.h"

namespace portcal {

namespace internal {

// Distance of `point` from the water ray of the air direction
// base + alpha e1 + beta e2, expressed in the fixed basis (b1, b2).
template <typename Port, typename S>
bool WaterRayMiss(const S* port, const VectorT<S, 3>& point, const Eigen::Vector3d& base,
                  const Eigen::Vector3d& e1, const Eigen::Vector3d& e2, const Eigen::Vector3d& b1,
                  const Eigen::Vector3d& b2, const S& alpha, const S& beta, S* miss) {
  const VectorT<S, 3> dir = base.cast<S>() + alpha * e1.cast<S>() + beta * e2.cast<S>();
  VectorT<S, 3> origin, water_dir;
  if (!Port::RayInWater(port, dir, &origin, &water_dir)) return false;
  VectorT<S, 3> q = point - origin;
  q -= q.dot(water_dir) * water_dir;
  miss[0] = b1.cast<S>().dot(q);
  miss[1] = b2.cast<S>().dot(q);
  return true;
}

// Any orthonormal pair perpendicular to the unit vector v.
inline void PerpendicularBasis(const Eigen::Vector3d& v, Eigen::Vector3d* a, Eigen::Vector3d* b) {
  *a = v.unitOrthogonal();
  *b = v.cross(*a);
}

}  // namespace internal

// Unit direction in air, from the camera centre, of the ray that reaches
// `point` (camera frame, in water). The value comes from the port's exact
// 1-D solve in the plane of refraction. For Jets, the derivatives come from
// the implicit function theorem: with the air direction perturbed by
// (alpha, beta) and m(alpha, beta; port, point) the miss distance of the
// water ray, one Newton step (alpha, beta) = -J^-1 m(0, 0) in T carries
// d(direction)/d(port, point) exactly, J from forward-mode autodiff.
// False if no ray reaches the point.
template <typename Port, typename T>
[[nodiscard]] bool AirRayToPoint(const T* port, const VectorT<T, 3>& point,
                                 VectorT<T, 3>* dir_in_air) {
  double port_value[Port::kNumParams];
  for (int i = 0; i < Port::kNumParams; ++i) port_value[i] = ScalarPart(port[i]);
  const Eigen::Vector3d point_value(ScalarPart(point[0]), ScalarPart(point[1]),
                                    ScalarPart(point[2]));
  Eigen::Vector3d base;
  if (!Port::AirRayToPointValue(port_value, point_value, &base)) return false;
  if constexpr (std::is_same_v<T, double>) {
    *dir_in_air = base;
    return true;
  } else {
    Eigen::Vector3d origin0, water_dir0;
    if (!Port::RayInWater(port_value, base, &origin0, &water_dir0)) {
      return false;
    }
    Eigen::Vector3d e1, e2, b1, b2;
    internal::PerpendicularBasis(base, &e1, &e2);
    internal::PerpendicularBasis(water_dir0, &b1, &b2);

    // One evaluation of the miss with a Jet over just (alpha, beta, port,
    // point) -- 13 wide for the flat port and the dome -- gives J and the
    // miss's derivatives by port and point; they are then chained into T
    // (whose width counts the pose's and intrinsics' parameters too), so
    // the refraction itself never runs in T's wider Jets.
    constexpr int kPortOffset = 2;
    constexpr int kPointOffset = 2 + Port::kNumParams;
    using Inner = ceres::Jet<double, kPointOffset + 3>;
    Inner port_inner[Port::kNumParams];
    for (int i = 0; i < Port::kNumParams; ++i) {
      port_inner[i] = Inner(port_value[i], kPortOffset + i);
    }
    VectorT<Inner, 3> point_inner;
    for (int k = 0; k < 3; ++k) point_inner[k] = Inner(point_value[k], kPointOffset + k);
    Inner miss_inner[2];
    if (!internal::WaterRayMiss<Port, Inner>(port_inner, point_inner, base, e1, e2, b1, b2,
                                             Inner(0.0, 0), Inner(0.0, 1), miss_inner)) {
      return false;
    }
    const double j00 = miss_inner[0].v[0], j01 = miss_inner[0].v[1];
    const double j10 = miss_inner[1].v[0], j11 = miss_inner[1].v[1];
    const double det = j00 * j11 - j01 * j10;
    if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;

    // miss(port, point) to first order about the values, in T.
    T miss[2];
    for (int r = 0; r < 2; ++r) {
      miss[r] = T(miss_inner[r].a);
      for (int i = 0; i < Port::kNumParams; ++i) {
        miss[r] += miss_inner[r].v[kPortOffset + i] * (port[i] - T(port_value[i]));
      }
      for (int k = 0; k < 3; ++k) {
        miss[r] += miss_inner[r].v[kPointOffset + k] * (point[k] - T(point_value[k]));
      }
    }
    const T alpha = -(j11 * miss[0] - j01 * miss[1]) / det;
    const T beta = -(-j10 * miss[0] + j00 * miss[1]) / det;
    *dir_in_air = (base.cast<T>() + alpha * e1.cast<T>() + beta * e2.cast<T>()).normalized();
    return true;
  }
}

// Point in water (camera frame) -> pixel, through the port and the lens.
template <typename CameraModel, typename Port, typename T>
[[nodiscard]] bool ImgFromWater(const T* intrinsics, const T* port,
                                const VectorT<T, 3>& point_in_cam, T* x, T* y) {
  VectorT<T, 3> dir;
  if (!AirRayToPoint<Port, T>(port, point_in_cam, &dir)) return false;
  return CameraModel::ImgFromCam(intrinsics, dir[0], dir[1], dir[2], x, y);
}

// Pixel -> ray in water (origin on the port's outer surface, unit
// direction), in the camera frame.
template <typename CameraModel, typename Port, typename T>
[[nodiscard]] bool WaterFromImg(const T* intrinsics, const T* port, const T& x, const T& y,
                                VectorT<T, 3>* origin, VectorT<T, 3>* dir) {
  T u, v;
  if (!CameraModel::CamFromImg(intrinsics, x, y, &u, &v)) return false;
  return Port::RayInWater(port, VectorT<T, 3>(u, v, T(1)), origin, dir);
}

}  // namespace portcal
