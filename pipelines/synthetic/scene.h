// What the renderer's rays can hit, each in its own frame: textured planar
// faces (targets, clutter), a rough seabed heightfield, opaque occluders.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"
#include "pipelines/synthetic/textures.h"

namespace portcal {

struct Hit {
  double t = 0;  // distance along the (unit) ray, metres
  float gray = 0;
};

class SceneObject {
 public:
  virtual ~SceneObject() = default;
  // Nearest hit with 0 < t < t_max of origin + t dir (object frame, dir unit).
  virtual bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                         Hit* hit) const = 0;
  // The same for a ray beside one that hit this object at t_near (the
  // renderer's neighbouring sample): objects found by iteration start there.
  virtual bool IntersectNear(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                             double t_max, double /*t_near*/, Hit* hit) const {
    return Intersect(origin, dir, t_max, hit);
  }
};

// A planar face z = 0 with a texture. The print faces the side its
// `front_normal_z` (+1 or -1) points to; rays hitting the other side see the
// back level.
struct Face {
  std::shared_ptr<const FaceTexture> texture;
  Rigid3d object_from_face;
  double front_normal_z = -1.0;
};

class FacesObject : public SceneObject {
 public:
  FacesObject(std::vector<Face> faces, float back_gray);
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                 Hit* hit) const override;

 private:
  struct Prepared {
    Face face;
    Eigen::Matrix3d face_from_object_rotation;
    Eigen::Vector3d face_from_object_translation;
  };
  std::vector<Prepared> faces_;
  float back_gray_;
};

// Seabed z = height(x, y) (world frame, z up): a sum of sinusoids of random
// direction and phase (gently rough), textured by a raster in (x, y).
class SeabedObject : public SceneObject {
 public:
  SeabedObject(std::shared_ptr<const FaceTexture> texture, double roughness_m, double wavelength_m,
               uint64_t seed);
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                 Hit* hit) const override;
  bool IntersectNear(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                     double t_near, Hit* hit) const override;
  double Height(double x, double y, Eigen::Vector2d* gradient = nullptr) const;

 private:
  std::shared_ptr<const FaceTexture> texture_;
  struct Wave {
    Eigen::Vector2d k;
    double amplitude, phase;
  };
  std::vector<Wave> waves_;
};

// An object placed in the camera frame of one image.
struct PlacedObject {
  const SceneObject* object = nullptr;
  Rigid3d cam_from_object;
};

// Nearest hit of a ray given in the camera frame among the placed objects.
bool IntersectScene(const std::vector<PlacedObject>& objects, const Eigen::Vector3d& origin,
                    const Eigen::Vector3d& dir, Hit* hit);

}  // namespace portcal
