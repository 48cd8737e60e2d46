// Refraction at a single interface and ray-sphere intersection, templated on
// the scalar (double or ceres::Jet) and on the dimension (3, or 2 inside the
// plane of refraction).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace portcal {

template <typename T, int Dim>
using VectorT = Eigen::Matrix<T, Dim, 1>;

// Snell's law in vector form (Glassner, "An Introduction to Ray Tracing",
// 1989; used for multi-layer flat ports by Agrawal et al., CVPR 2012):
//   t = r d + (sqrt(1 - r^2 (1 - c^2)) - r c) n,  r = n1 / n2,  c = n . d
// d: unit direction of the incoming ray; n: unit normal of the interface on
// the side the ray goes to (n . d > 0). Writes the unit refracted direction.
// False on total internal reflection (or a ray that does not cross).
template <typename T, int Dim>
[[nodiscard]] bool Refract(const VectorT<T, Dim>& d, const VectorT<T, Dim>& n, const T& index_ratio,
                           VectorT<T, Dim>* refracted) {
  using std::sqrt;
  const T c = n.dot(d);
  if (!(c > T(0))) return false;
  const T k = T(1) - index_ratio * index_ratio * (T(1) - c * c);
  if (!(k > T(0))) return false;  // total internal reflection
  *refracted = index_ratio * d + (sqrt(k) - index_ratio * c) * n;
  return true;
}

// Distance s > 0 along the unit direction d from `origin` (inside the sphere)
// to the sphere of `radius` around `center`. False if the origin is not
// strictly inside (then the discriminant may vanish).
template <typename T, int Dim>
[[nodiscard]] bool ExitDistanceFromInside(const VectorT<T, Dim>& origin, const VectorT<T, Dim>& d,
                                          const VectorT<T, Dim>& center, const T& radius, T* s) {
  using std::sqrt;
  const VectorT<T, Dim> q = origin - center;
  const T c = q.squaredNorm() - radius * radius;
  if (!(c < T(0))) return false;
  const T b = d.dot(q);
  // s^2 + 2 b s + c = 0 with c < 0: one positive root. Written in the
  // cancellation-free form for b > 0.
  const T disc = sqrt(b * b - c);
  *s = b > T(0) ? -c / (b + disc) : disc - b;
  return true;
}

}  // namespace portcal
