#include "pipelines/reconstruction/ray_geometry.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opengv/absolute_pose/NoncentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

#include "colmap_ext/util/random_seed.h"

namespace portcal {

Ray3d RayInWorld(const Ray3d& ray_in_cam, const Rigid3d& cam_from_world) {
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  Ray3d ray;
  ray.origin = world_from_cam * ray_in_cam.origin;
  ray.direction = world_from_cam.rotation * ray_in_cam.direction;
  return ray;
}

std::optional<Eigen::Vector3d> TriangulateRays(const std::vector<Ray3d>& rays) {
  if (rays.size() < 2) return std::nullopt;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Ray3d& ray : rays) {
    const Eigen::Vector3d d = ray.direction.normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * ray.origin;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(2) > 1e-9 * s(0))) return std::nullopt;
  const Eigen::Vector3d x = svd.solve(b);
  if (!x.allFinite()) return std::nullopt;
  return x;
}

double MaxTriangulationAngle(const std::vector<Ray3d>& rays, const Eigen::Vector3d& point) {
  double best = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d a = (point - rays[i].origin).normalized();
    for (size_t j = i + 1; j < rays.size(); ++j) {
      const Eigen::Vector3d b = (point - rays[j].origin).normalized();
      best = std::max(best, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
    }
  }
  return best;
}

std::optional<Rigid3d> EstimateGeneralizedAbsolutePose(
    const std::vector<Ray3d>& rays_in_cam, const std::vector<Eigen::Vector3d>& points,
    const GeneralizedAbsolutePoseOptions& options, std::vector<char>* inliers) {
  const size_t n = rays_in_cam.size();
  inliers->assign(n, 0);
  if (n < 6 || static_cast<int>(n) < options.min_num_inliers) return std::nullopt;
  // Every ray is its own "camera" of the generalized camera: offset = the
  // ray's origin, no rotation, bearing = its direction.
  opengv::bearingVectors_t bearings;
  opengv::points_t world;
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  std::vector<int> correspondences;
  for (size_t i = 0; i < n; ++i) {
    bearings.push_back(rays_in_cam[i].direction.normalized());
    world.push_back(points[i]);
    offsets.push_back(rays_in_cam[i].origin);
    rotations.push_back(Eigen::Matrix3d::Identity());
    correspondences.push_back(static_cast<int>(i));
  }
  opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(bearings, correspondences, world,
                                                           offsets, rotations);
  using Problem = opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;
  opengv::sac::Ransac<Problem> ransac;
  // Deterministic: OpenGV seeds its generator from the clock unless told.
  std::shared_ptr<Problem> problem(new Problem(adapter, Problem::GP3P, false));
  problem->rng_alg_.seed(GeneratorState(options.random_seed));
  ransac.sac_model_ = problem;
  ransac.threshold_ = 1.0 - std::cos(options.max_angle_error_rad);
  ransac.max_iterations_ = options.max_iterations;
  ransac.probability_ = options.confidence;
  if (!ransac.computeModel() ||
      static_cast<int>(ransac.inliers_.size()) < options.min_num_inliers) {
    return std::nullopt;
  }
  adapter.sett(ransac.model_coefficients_.col(3));
  adapter.setR(ransac.model_coefficients_.block<3, 3>(0, 0));
  const opengv::transformation_t refined =
      opengv::absolute_pose::optimize_nonlinear(adapter, ransac.inliers_);
  // OpenGV returns the camera's pose in the world: [R | t] = world_from_cam.
  const Eigen::Matrix3d R = refined.block<3, 3>(0, 0);
  const Eigen::Vector3d t = refined.col(3);
  if (!R.allFinite() || !t.allFinite()) return std::nullopt;
  const Rigid3d world_from_cam(Eigen::Quaterniond(R).normalized(), t);
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  int count = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d in_cam = cam_from_world * points[i];
    const Eigen::Vector3d d = (in_cam - rays_in_cam[i].origin).normalized();
    const double angle =
        std::acos(std::clamp(d.dot(rays_in_cam[i].direction.normalized()), -1.0, 1.0));
    (*inliers)[i] = angle < options.max_angle_error_rad;
    count += (*inliers)[i];
  }
  if (count < options.min_num_inliers) return std::nullopt;
  return cam_from_world;
}

std::optional<Rigid3d> EstimateRelativePose(const std::vector<Eigen::Vector3d>& directions1,
                                            const std::vector<Eigen::Vector3d>& directions2,
                                            double max_angle_error_rad, int random_seed,
                                            std::vector<char>* inliers) {
  const size_t n = directions1.size();
  inliers->assign(n, 0);
  std::vector<cv::Point2d> p1, p2;
  std::vector<size_t> index;
  for (size_t i = 0; i < n; ++i) {
    // Rays at 90 degrees or more from the optical axis have no image
    // coordinates; they are left out of the essential matrix.
    if (directions1[i].z() < 1e-3 || directions2[i].z() < 1e-3) continue;
    p1.emplace_back(directions1[i].x() / directions1[i].z(),
                    directions1[i].y() / directions1[i].z());
    p2.emplace_back(directions2[i].x() / directions2[i].z(),
                    directions2[i].y() / directions2[i].z());
    index.push_back(i);
  }
  if (p1.size() < 8) return std::nullopt;
  cv::Mat mask;
  cv::theRNG() = cv::RNG(GeneratorState(random_seed));
  const cv::Mat E = cv::findEssentialMat(p1, p2, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC, 0.9999,
                                         max_angle_error_rad, 2000, mask);
  if (E.rows != 3 || E.cols != 3) return std::nullopt;
  cv::Mat R, t;
  if (cv::recoverPose(E, p1, p2, cv::Mat::eye(3, 3, CV_64F), R, t, mask) < 8) return std::nullopt;
  for (size_t k = 0; k < index.size(); ++k)
    (*inliers)[index[k]] = mask.at<uchar>(static_cast<int>(k)) != 0;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(R, rotation);
  cv::cv2eigen(t, translation);
  return Rigid3d(Eigen::Quaterniond(rotation).normalized(), translation.normalized());
}

std::optional<double> FocalLengthFromMarkers(const std::vector<MarkerQuad>& markers, double cx,
                                             double cy) {
  // Homography from the unit square (0,0),(1,0),(1,1),(0,1) to the corners
  // centred on the principal point.
  std::vector<double> estimates;
  const std::vector<cv::Point2f> square = {
      {0, 0}, {1, 0}, {1, 1}, {0, 1}};  // OpenCV wants floats here
  for (const MarkerQuad& marker : markers) {
    std::vector<cv::Point2f> image;
    for (const Eigen::Vector2d& c : marker.corners) {
      image.emplace_back(static_cast<float>(c.x() - cx), static_cast<float>(c.y() - cy));
    }
    const cv::Mat Hcv = cv::getPerspectiveTransform(square, image);
    if (Hcv.empty()) continue;
    Eigen::Matrix3d H;
    cv::cv2eigen(Hcv, H);
    const Eigen::Vector3d h1 = H.col(0), h2 = H.col(1);
    // With K = diag(f, f, 1): omega ~ diag(1, 1, f^2). h1' w h2 = 0 and
    // h1' w h1 = h2' w h2 are linear in a = f^2.
    const double a1 = h1.z() * h2.z();
    const double b1 = -(h1.x() * h2.x() + h1.y() * h2.y());
    const double a2 = h1.z() * h1.z() - h2.z() * h2.z();
    const double b2 = -(h1.x() * h1.x() + h1.y() * h1.y() - h2.x() * h2.x() - h2.y() * h2.y());
    // Least squares of the two. A marker seen fronto-parallel makes a1 and
    // a2 vanish (f unobservable) and gives a wild or negative value; the
    // median over many markers ignores those.
    if (a1 == 0 && a2 == 0) continue;
    const double f2 = (a1 * b1 + a2 * b2) / (a1 * a1 + a2 * a2);
    if (f2 > 0 && std::isfinite(f2)) estimates.push_back(std::sqrt(f2));
  }
  if (estimates.size() < 3) return std::nullopt;
  std::nth_element(estimates.begin(), estimates.begin() + estimates.size() / 2, estimates.end());
  return estimates[estimates.size() / 2];
}

}  // namespace portcal
