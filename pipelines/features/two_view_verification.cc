#include "pipelines/features/two_view_verification.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <optional>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/random_seed.h"
#include "pipelines/features/relative_pose_refinement.h"

namespace portcal {

void TwoViewVerificationOptions::Check() const {
  if (!(max_error > 0)) throw OptionError("--TwoViewGeometry.max_error", max_error, "> 0 px");
  if (!(confidence > 0 && confidence < 1)) {
    throw OptionError("--TwoViewGeometry.confidence", confidence, "in (0, 1)");
  }
  if (max_num_trials < 1) {
    throw OptionError("--TwoViewGeometry.max_num_trials", max_num_trials, ">= 1");
  }
  if (random_seed < 0) throw OptionError("--random_seed", random_seed, ">= 0");
  if (min_num_inliers < 8) {
    throw OptionError("--TwoViewGeometry.min_num_inliers", min_num_inliers, ">= 8");
  }
  if (!(min_inlier_ratio >= 0 && min_inlier_ratio <= 1)) {
    throw OptionError("--TwoViewGeometry.min_inlier_ratio", min_inlier_ratio, "in [0, 1]");
  }
}

namespace {

FeatureMatches Inliers(const FeatureMatches& matches, const std::vector<int>& indices,
                       const cv::Mat& mask) {
  FeatureMatches inliers;
  if (mask.empty()) return inliers;
  for (size_t k = 0; k < indices.size(); ++k) {
    if (mask.at<uchar>(static_cast<int>(k)))
      inliers.push_back(matches[static_cast<size_t>(indices[k])]);
  }
  return inliers;
}

// The matches' pixels as stored (COLMAP convention, like the F and H
// COLMAP writes) and, where both back-project, their normalised image
// coordinates.
struct MatchedPoints {
  std::vector<cv::Point2d> pixels1, pixels2, rays1, rays2;
  std::vector<int> ray_index;  // match index of each normalised pair
};

MatchedPoints PointsOfMatches(const Camera& camera1, const FeatureKeypoints& keypoints1,
                              const Camera& camera2, const FeatureKeypoints& keypoints2,
                              const FeatureMatches& matches) {
  MatchedPoints out;
  for (size_t m = 0; m < matches.size(); ++m) {
    const FeatureKeypoint& k1 = keypoints1.at(matches[m].point2D_idx1);
    const FeatureKeypoint& k2 = keypoints2.at(matches[m].point2D_idx2);
    out.pixels1.emplace_back(k1.x, k1.y);
    out.pixels2.emplace_back(k2.x, k2.y);
    const auto r1 = camera1.CamFromImg(Eigen::Vector2d(k1.x, k1.y));
    const auto r2 = camera2.CamFromImg(Eigen::Vector2d(k2.x, k2.y));
    if (r1 && r2) {
      out.rays1.emplace_back(r1->x() / r1->z(), r1->y() / r1->z());
      out.rays2.emplace_back(r2->x() / r2->z(), r2->y() / r2->z());
      out.ray_index.push_back(static_cast<int>(m));
    }
  }
  return out;
}

// The same restricted to F's inliers (`f_mask` over all matches).
MatchedPoints FInliersOf(const MatchedPoints& all, const cv::Mat& f_mask,
                         std::vector<int>* f_index) {
  MatchedPoints out;
  for (size_t k = 0; k < all.pixels1.size(); ++k) {
    if (!f_mask.at<uchar>(static_cast<int>(k))) continue;
    f_index->push_back(static_cast<int>(k));
    out.pixels1.push_back(all.pixels1[k]);
    out.pixels2.push_back(all.pixels2[k]);
  }
  for (size_t k = 0; k < all.ray_index.size(); ++k) {
    const size_t m = static_cast<size_t>(all.ray_index[k]);
    if (!f_mask.at<uchar>(static_cast<int>(m))) continue;
    out.ray_index.push_back(all.ray_index[k]);
    out.rays1.push_back(all.rays1[k]);
    out.rays2.push_back(all.rays2[k]);
  }
  return out;
}

// Relative pose of a calibrated pair (unit baseline) from E's inliers: E's
// decomposition in front of both cameras, then fitted to all the inliers
// (relative_pose_refinement.h) under a Cauchy loss of a quarter of the
// inlier threshold (1 px at the default 4), the scale of a true match's
// noise, not of the chance matches the threshold lets in.
std::optional<Rigid3d> PoseFromEssential(const cv::Mat& E, const MatchedPoints& e_points,
                                         const cv::Mat& e_mask, double threshold) {
  std::vector<cv::Point2d> in1, in2;
  std::vector<Eigen::Vector2d> points1, points2;
  for (size_t k = 0; k < e_points.ray_index.size(); ++k) {
    if (e_mask.at<uchar>(static_cast<int>(k))) {
      in1.push_back(e_points.rays1[k]);
      in2.push_back(e_points.rays2[k]);
      points1.emplace_back(in1.back().x, in1.back().y);
      points2.emplace_back(in2.back().x, in2.back().y);
    }
  }
  cv::Mat R, t;
  if (cv::recoverPose(E, in1, in2, cv::Mat::eye(3, 3, CV_64F), R, t) <= 0) return std::nullopt;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(R, rotation);
  cv::cv2eigen(t, translation);
  const Rigid3d from_sample(Eigen::Quaterniond(rotation), translation);
  return RefineRelativePose(points1, points2, from_sample, threshold / 4).value_or(from_sample);
}

}  // namespace

TwoViewGeometry VerifyTwoView(const Camera& camera1, const FeatureKeypoints& keypoints1,
                              const Camera& camera2, const FeatureKeypoints& keypoints2,
                              const FeatureMatches& matches,
                              const TwoViewVerificationOptions& options) {
  TwoViewGeometry geometry;
  geometry.config = TwoViewGeometryConfig::kDegenerate;
  if (static_cast<int>(matches.size()) < options.min_num_inliers) return geometry;
  const MatchedPoints points = PointsOfMatches(camera1, keypoints1, camera2, keypoints2, matches);
  std::vector<int> all(matches.size());
  for (size_t m = 0; m < all.size(); ++m) all[m] = static_cast<int>(m);

  // F first, by LO-RANSAC over all matches (two_view_verification.h). E
  // and H are then searched among F's inliers only: both models' inliers
  // satisfy the epipolar constraint, so this loses nothing COLMAP's rules
  // use (they compare the counts), and RANSAC on a clean set needs few
  // iterations where the 5-point solver on the raw matches would need
  // thousands.
  cv::Mat f_mask, e_mask, h_mask;
  const cv::Mat F =
      cv::findFundamentalMat(points.pixels1, points.pixels2, cv::USAC_DEFAULT, options.max_error,
                             options.confidence, options.max_num_trials, f_mask);
  const FeatureMatches f_inliers = F.rows == 3 ? Inliers(matches, all, f_mask) : FeatureMatches();
  // E's inliers are a subset of F's, so with fewer than the minimum here
  // neither model can pass COLMAP's rules below: the pair is degenerate
  // whatever E and H say, and their RANSAC (up to max_num_trials each on a
  // pair of unrelated images) is skipped.
  const double min_inliers =
      std::max<double>(options.min_num_inliers, options.min_inlier_ratio * matches.size());
  if (static_cast<double>(f_inliers.size()) < min_inliers) {
    if (F.rows == 3) cv::cv2eigen(F, geometry.F);
    return geometry;
  }
  std::vector<int> f_index;  // match indices of F's inliers
  const MatchedPoints f_points = FInliersOf(points, f_mask, &f_index);
  cv::Mat E;
  const double focal = 0.5 * (camera1.MeanFocalLength() + camera2.MeanFocalLength());
  if (static_cast<int>(f_points.rays1.size()) >= options.min_num_inliers) {
    cv::theRNG() = cv::RNG(GeneratorState(options.random_seed));
    E = cv::findEssentialMat(f_points.rays1, f_points.rays2, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC,
                             options.confidence, options.max_error / focal, options.max_num_trials,
                             e_mask);
  }
  cv::theRNG() = cv::RNG(GeneratorState(options.random_seed));
  const cv::Mat H =
      cv::findHomography(f_points.pixels1, f_points.pixels2, cv::RANSAC, options.max_error, h_mask,
                         options.max_num_trials, options.confidence);
  const FeatureMatches e_inliers =
      E.rows == 3 ? Inliers(matches, f_points.ray_index, e_mask) : FeatureMatches();
  const FeatureMatches h_inliers =
      H.rows == 3 ? Inliers(matches, f_index, h_mask) : FeatureMatches();
  const double nf = static_cast<double>(f_inliers.size());
  const double ne = static_cast<double>(e_inliers.size());
  const double nh = static_cast<double>(h_inliers.size());

  if (F.rows == 3) cv::cv2eigen(F, geometry.F);
  if (E.rows == 3) cv::cv2eigen(E, geometry.E);
  if (H.rows == 3) cv::cv2eigen(H, geometry.H);
  if (ne >= min_inliers && nf > 0 && ne / nf >= options.min_E_F_inlier_ratio) {
    geometry.config = nh / ne > options.max_H_inlier_ratio
                          ? TwoViewGeometryConfig::kPlanarOrPanoramic
                          : TwoViewGeometryConfig::kCalibrated;
    geometry.inlier_matches = e_inliers;
    if (const auto pose = PoseFromEssential(E, f_points, e_mask, options.max_error / focal))
      geometry.cam2_from_cam1 = *pose;
  } else if (nf >= min_inliers) {
    geometry.config = nh / nf > options.max_H_inlier_ratio
                          ? TwoViewGeometryConfig::kPlanarOrPanoramic
                          : TwoViewGeometryConfig::kUncalibrated;
    geometry.inlier_matches = f_inliers;
    geometry.E.setZero();
  }
  return geometry;
}

}  // namespace portcal
