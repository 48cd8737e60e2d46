// Geometry on rays (possibly refracted, i.e. not through one centre): the
// pieces incremental refractive structure-from-motion is built from.
#pragma once

#include <optional>
#include <vector>

#include "colmap_ext/geometry/rigid3d.h"
#include "colmap_ext/housing/housing.h"

namespace portcal {

// A ray moved from the camera into the world frame.
Ray3d RayInWorld(const Ray3d& ray_in_cam, const Rigid3d& cam_from_world);

// The point closest to all rays in the least-squares sense (sum of squared
// distances to the lines; the generalisation of the midpoint method).
// nullopt when the rays are (nearly) parallel.
std::optional<Eigen::Vector3d> TriangulateRays(const std::vector<Ray3d>& rays_in_world);

// Largest angle (radians) between the directions from the rays' origins to
// `point`: COLMAP's triangulation angle generalised to non-central rays.
double MaxTriangulationAngle(const std::vector<Ray3d>& rays_in_world, const Eigen::Vector3d& point);

struct GeneralizedAbsolutePoseOptions {
  double max_angle_error_rad = 0.004;  // inlier threshold on the ray angle
  double confidence = 0.9999;
  int max_iterations = 2000;
  int min_num_inliers = 12;
  int random_seed = 0;  // RANSAC's samples (random_seed.h)
};

// cam_from_world of a non-central camera from rays in the camera frame and
// the world points they see: OpenGV's gp3p (Kneip, Furgale and Siegwart
// 2013) in RANSAC, then OpenGV's non-linear refinement on the inliers.
// `inliers` gets a flag per correspondence. nullopt when too few inliers.
std::optional<Rigid3d> EstimateGeneralizedAbsolutePose(
    const std::vector<Ray3d>& rays_in_cam, const std::vector<Eigen::Vector3d>& points_in_world,
    const GeneralizedAbsolutePoseOptions& options, std::vector<char>* inliers);

// Relative pose of two views from the directions of corresponding rays,
// treating each camera as central (the port offsets the rays by millimetres
// against baselines of decimetres; bundle adjustment later uses the exact
// rays). Essential matrix by RANSAC, then the cheirality test. The
// translation has unit length. `inliers` gets a flag per correspondence.
std::optional<Rigid3d> EstimateRelativePose(const std::vector<Eigen::Vector3d>& directions1,
                                            const std::vector<Eigen::Vector3d>& directions2,
                                            double max_angle_error_rad, int random_seed,
                                            std::vector<char>* inliers);

// Focal length from ArUco markers: each marker is a planar square seen in
// one view, and with the principal point at (cx, cy), square pixels and no
// skew Zhang's two constraints on the image of the absolute conic
// (Zhang 2000, eq. 3-4) each give f^2 in closed form. Returns the median
// over all usable constraints, or nullopt if there are fewer than three.
struct MarkerQuad {
  std::array<Eigen::Vector2d, 4> corners;  // COLMAP pixels, OpenCV's order
};
std::optional<double> FocalLengthFromMarkers(const std::vector<MarkerQuad>& markers, double cx,
                                             double cy);

}  // namespace portcal
