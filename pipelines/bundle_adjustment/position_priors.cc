#include "pipelines/bundle_adjustment/position_priors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "colmap_ext/cost/position_prior_error.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

namespace {

struct CentreAndPrior {
  image_t image_id;
  Eigen::Vector3d centre;
  Eigen::Vector3d prior;
};

std::vector<CentreAndPrior> Collect(const Reconstruction& r) {
  std::vector<CentreAndPrior> pairs;
  for (const auto& [id, pose] : r.poses()) {
    const auto& prior = r.inputs().images.at(id).position_prior;
    if (prior) pairs.push_back({id, pose.Inverse().translation, *prior});
  }
  return pairs;
}

// The priors span at least a line with an off-line point: the second
// singular value of the centred priors is not negligible.
bool SpansPlane(const std::vector<CentreAndPrior>& pairs) {
  if (pairs.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pairs) mean += p.prior;
  mean /= static_cast<double>(pairs.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : pairs) scatter += (p.prior - mean) * (p.prior - mean).transpose();
  const Eigen::Vector3d s = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues();
  return s[2] > 0 && s[1] > 1e-6 * s[2];
}

Similarity3d Fit(const std::vector<CentreAndPrior>& pairs, const std::vector<char>& use) {
  const int n = static_cast<int>(std::count(use.begin(), use.end(), 1));
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  int k = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!use[i]) continue;
    src.col(k) = pairs[i].centre;
    dst.col(k) = pairs[i].prior;
    ++k;
  }
  return FitSimilarity(src, dst);
}

Eigen::Vector3d Apply(const Similarity3d& s, const Eigen::Vector3d& x) {
  return s.scale * (s.rotation * x) + s.translation;
}

}  // namespace

Similarity3d FitSimilarity(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  const Eigen::Matrix4d m = Eigen::umeyama(from, to, true);
  Similarity3d sim;
  sim.scale = m.block<3, 1>(0, 0).norm();
  sim.rotation = Eigen::Quaterniond(m.block<3, 3>(0, 0) / sim.scale).normalized();
  sim.translation = m.block<3, 1>(0, 3);
  return sim;
}

int NumUsablePositionPriors(const Reconstruction& reconstruction) {
  const std::vector<CentreAndPrior> pairs = Collect(reconstruction);
  return SpansPlane(pairs) ? static_cast<int>(pairs.size()) : 0;
}

std::optional<PositionPriorAlignment> AlignToPositionPriors(Reconstruction* r,
                                                            double min_inlier_distance_m) {
  const std::vector<CentreAndPrior> pairs = Collect(*r);
  if (!SpansPlane(pairs)) return std::nullopt;
  std::vector<char> use(pairs.size(), 1);
  Similarity3d sim = Fit(pairs, use);
  std::vector<double> errors(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i)
    errors[i] = (Apply(sim, pairs[i].centre) - pairs[i].prior).norm();
  std::vector<double> sorted = errors;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(3.0 * 1.4826 * sorted[sorted.size() / 2], min_inlier_distance_m);
  for (size_t i = 0; i < pairs.size(); ++i) use[i] = errors[i] <= limit;
  std::vector<CentreAndPrior> inliers;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (use[i]) inliers.push_back(pairs[i]);
  }
  if (SpansPlane(inliers)) sim = Fit(pairs, use);

  PositionPriorAlignment alignment;
  alignment.new_from_old = sim;
  alignment.num_priors = static_cast<int>(pairs.size());
  alignment.num_inliers = static_cast<int>(inliers.size());
  double sum_sq = 0;
  for (const auto& p : inliers) sum_sq += (Apply(sim, p.centre) - p.prior).squaredNorm();
  alignment.rms_m = inliers.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(inliers.size()));

  // Camera frames scale with the world (their coordinates are metres too):
  // cam_from_new = (R_c R^T, s t_c - R_c R^T t).
  for (auto& [id, pose] : r->mutable_poses()) {
    const Eigen::Quaterniond rotation = pose.rotation * sim.rotation.conjugate();
    pose =
        Rigid3d(rotation.normalized(), sim.scale * pose.translation - rotation * sim.translation);
  }
  std::vector<point3D_t> ids;
  for (const auto& [id, point] : r->points()) ids.push_back(id);
  for (point3D_t id : ids) r->point(id).xyz = Apply(sim, r->points().at(id).xyz);
  alignment.num_unprojectable_deleted = r->DeleteUnprojectableObservations();
  VLOG_IF(1, alignment.num_unprojectable_deleted > 0)
      << "aligned to the position priors: " << alignment.num_unprojectable_deleted
      << " observations that cannot be projected any more deleted";
  return alignment;
}

ceres::CostFunction* CreatePositionPriorCost(const Eigen::Vector3d& prior, double sigma_m) {
  return PositionPriorError::Create(prior, sigma_m);
}

}  // namespace portcal
