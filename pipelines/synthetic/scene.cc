#include "pipelines/synthetic/scene.h"

#include <cmath>
#include <random>

namespace portcal {

FacesObject::FacesObject(std::vector<Face> faces, float back_gray) : back_gray_(back_gray) {
  for (Face& face : faces) {
    const Rigid3d face_from_object = face.object_from_face.Inverse();
    faces_.push_back({std::move(face), face_from_object.rotation.toRotationMatrix(),
                      face_from_object.translation});
  }
}

bool FacesObject::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                            Hit* hit) const {
  bool found = false;
  for (const Prepared& p : faces_) {
    const Eigen::Vector3d o = p.face_from_object_rotation * origin + p.face_from_object_translation;
    const double dz = p.face_from_object_rotation.row(2).dot(dir);
    if (std::abs(dz) < 1e-15) continue;
    const double t = -o.z() / dz;
    if (!(t > 1e-9 && t < t_max)) continue;
    const double x = o.x() + t * p.face_from_object_rotation.row(0).dot(dir);
    const double y = o.y() + t * p.face_from_object_rotation.row(1).dot(dir);
    float gray;
    if (!p.face.texture->Gray(x, y, &gray)) continue;
    // The print is seen when the ray travels against its front normal.
    const bool front = dz * p.face.front_normal_z < 0;
    t_max = t;
    hit->t = t;
    hit->gray = front ? gray : back_gray_;
    found = true;
  }
  return found;
}

SeabedObject::SeabedObject(std::shared_ptr<const FaceTexture> texture, double roughness_m,
                           double wavelength_m, uint64_t seed)
    : texture_(std::move(texture)) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), scale(0.5, 1.5);
  // Five waves; amplitudes chosen so the sum's standard deviation is
  // roughness_m (each sinusoid has variance a^2 / 2).
  const int n = 5;
  const double amplitude = roughness_m * std::sqrt(2.0 / n);
  for (int i = 0; i < n; ++i) {
    const double a = angle(rng), lambda = wavelength_m * scale(rng);
    waves_.push_back(
        {Eigen::Vector2d(std::cos(a), std::sin(a)) * (2 * M_PI / lambda), amplitude, angle(rng)});
  }
}

double SeabedObject::Height(double x, double y, Eigen::Vector2d* gradient) const {
  double h = 0;
  if (gradient) gradient->setZero();
  for (const Wave& w : waves_) {
    const double arg = w.k.x() * x + w.k.y() * y + w.phase;
    h += w.amplitude * std::sin(arg);
    if (gradient) *gradient += w.amplitude * std::cos(arg) * w.k;
  }
  return h;
}

bool SeabedObject::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                             double t_max, Hit* hit) const {
  return IntersectNear(origin, dir, t_max, 0.0, hit);  // from the mean plane
}

bool SeabedObject::IntersectNear(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                 double t_max, double t_near, Hit* hit) const {
  if (!(dir.z() < -1e-6)) return false;  // looking down only
  // Newton on f(t) = z(t) - height(x(t), y(t)) from t_near, or from the
  // mean plane when there is none; the relief is gentle (slopes << 1), so a
  // few iterations converge. Its convergence is quadratic: after a step s
  // the error is about |f''| / (2 |f'|) s^2 with
  // |f''| <= sum of a k^2 (19 / m for the surveys' relief, 0.15 m over
  // 2 m; 100 times that for a relief ten times finer), so stopping after a
  // step under 1e-6 m leaves the hit within ~1e-11 m (~1e-9 m) without
  // spending one more evaluation (5 sincos) to confirm it.
  double t = t_near > 0 ? t_near : -origin.z() / dir.z();
  for (int iter = 0; iter < 20; ++iter) {
    const Eigen::Vector3d p = origin + t * dir;
    Eigen::Vector2d gradient;
    const double f = p.z() - Height(p.x(), p.y(), &gradient);
    const double df = dir.z() - gradient.dot(dir.head<2>());
    if (std::abs(df) < 1e-12) return false;
    const double step = f / df;
    t -= step;
    if (std::abs(step) < 1e-6) break;
  }
  if (!(t > 1e-9 && t < t_max)) return false;
  const Eigen::Vector3d p = origin + t * dir;
  float gray;
  if (!texture_->Gray(p.x(), p.y(), &gray)) return false;
  hit->t = t;
  hit->gray = gray;
  return true;
}

bool IntersectScene(const std::vector<PlacedObject>& objects, const Eigen::Vector3d& origin,
                    const Eigen::Vector3d& dir, Hit* hit) {
  bool found = false;
  double t_max = 1e300;
  for (const PlacedObject& placed : objects) {
    const Rigid3d object_from_cam = placed.cam_from_object.Inverse();
    Hit candidate;
    if (placed.object->Intersect(object_from_cam * origin, object_from_cam.rotation * dir, t_max,
                                 &candidate)) {
      *hit = candidate;
      t_max = candidate.t;
      found = true;
    }
  }
  return found;
}

}  // namespace portcal
