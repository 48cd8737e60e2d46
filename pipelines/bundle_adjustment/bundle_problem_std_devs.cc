// BundleProblem's standard deviations: the marginal covariance of the
// calibration blocks (calibration_covariance.h) and what to name when it
// cannot be computed.
#include <sstream>

#include "colmap_ext/util/logging.h"
#include "pipelines/bundle_adjustment/bundle_problem.h"
#include "pipelines/bundle_adjustment/reduced_camera_system.h"

namespace portcal {

// What a parameter block is, for the covariance's error messages.
std::string BundleProblem::Describe(const double* block, int index) const {
  for (const auto& [id, b] : pose_blocks_) {
    if (b.data() == block) {
      return "the pose of image '" + reconstruction_->inputs().images.at(id).name + "' (tangent " +
             std::to_string(index) + ")";
    }
  }
  for (const auto& [id, b] : intrinsics_) {
    if (b.data() == block)
      return "an intrinsic parameter of camera " + std::to_string(id) +
             " (refined ones: " + cameras_.at(id).camera.ParamsInfo() + ")";
  }
  for (const auto& [id, b] : housings_) {
    if (b.data() == block) return "a housing parameter of camera " + std::to_string(id);
  }
  return "a marker corner";
}

// A residual by its parameter blocks (see AddPoints, AddMarkers and
// AddPositionPriors for their order).
std::string BundleProblem::DescribeResidual(const std::vector<double*>& blocks) const {
  std::string image;
  for (const auto& [id, block] : pose_blocks_) {
    if (block.data() == blocks[0])
      image = "image '" + reconstruction_->inputs().images.at(id).name + "'";
  }
  if (image.empty()) return "a marker's side";
  if (blocks.size() == 1) return "the position prior of " + image;
  for (const auto& [id, xyz] : point_blocks_) {
    if (xyz.data() == blocks[1])
      return "the observation of 3D point " + std::to_string(id) + " in " + image;
  }
  return "the observation of a marker corner in " + image;
}

void BundleProblem::ComputeStdDevs(const ceres::Solver::Summary& summary,
                                   CalibrationStdDevs* std_devs) {
  std_devs->num_residuals = num_residuals_;
  const double dof = std::max<double>(
      1.0, summary.num_residuals_reduced - summary.num_effective_parameters_reduced);
  // sigma0^2 = sum of squared (sigma-normalised) residuals / dof, from the
  // unrobustified residuals.
  double sum_sq = 0;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  std::vector<double> residuals;
  problem_.Evaluate(evaluate, nullptr, &residuals, nullptr, nullptr);
  for (double r : residuals) sum_sq += r * r;
  std_devs->sigma0 = std::sqrt(sum_sq / dof) * options_.sigma_px;
  const double scale = std::sqrt(sum_sq / dof);
  const auto is_free = [&](const double* block) {
    return problem_.HasParameterBlock(block) && !problem_.IsParameterBlockConstant(block);
  };
  std::vector<double*> points, others;
  std::vector<const double*> wanted;
  for (auto& [id, xyz] : point_blocks_) {
    if (is_free(xyz.data())) points.push_back(xyz.data());
  }
  for (auto& [id, block] : pose_blocks_) {
    if (is_free(block.data())) others.push_back(block.data());
  }
  if (use_markers_) {
    for (MarkerCorner& corner : *markers_) {
      if (is_free(corner.xyz.data())) others.push_back(corner.xyz.data());
    }
  }
  for (camera_t id : used_cameras_) {
    if (is_free(intrinsics_.at(id).data())) {
      others.push_back(intrinsics_.at(id).data());
      wanted.push_back(intrinsics_.at(id).data());
    }
    if (housings_.count(id) && is_free(housings_.at(id).data())) {
      others.push_back(housings_.at(id).data());
      wanted.push_back(housings_.at(id).data());
    }
  }
  if (wanted.empty()) return;
  ResidualClusters clusters;
  int image_index = 0;
  for (const auto& [id, block] : pose_blocks_)
    clusters.image_of_block[block.data()] = image_index++;
  // The marginalised points are tracks by themselves; a marker's corner,
  // seen in several images, is one too.
  if (use_markers_) {
    int corner_index = 0;
    for (MarkerCorner& corner : *markers_)
      clusters.track_of_block[corner.xyz.data()] = corner_index++;
  }
  clusters.residuals_per_dof = summary.num_residuals_reduced / dof;
  const auto start = std::chrono::steady_clock::now();
  const auto describe = [this](const double* block, int index) { return Describe(block, index); };
  const MarginalCovariance marginal =
      ComputeMarginalCovariance(&problem_, points, others, wanted, scale, describe, &clusters,
                                /*max_dense_size=*/1200, options_.num_threads);
  LOG(INFO) << "bundle adjustment: covariance of " << others.size()
            << " pose and calibration blocks, " << points.size()
            << " points marginalised, clustered by " << marginal.num_clusters << " images and "
            << marginal.num_tracks << " tracks: "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s";
  StoreStdDevs(marginal, std_devs);
}

// Each camera's standard deviations, the larger of the noise's and the
// clusters' estimates, and the correlations of its intrinsics with its
// housing.
void BundleProblem::StoreStdDevs(const MarginalCovariance& marginal,
                                 CalibrationStdDevs* std_devs) const {
  const auto larger = [](std::vector<double> by_noise, const std::vector<double>& by_clusters) {
    for (size_t i = 0; i < by_clusters.size() && i < by_noise.size(); ++i) {
      by_noise[i] = std::max(by_noise[i], by_clusters[i]);
    }
    return by_noise;
  };
  for (camera_t id : used_cameras_) {
    const double* intrinsics_block = intrinsics_.at(id).data();
    const bool free_intrinsics = marginal.offset.count(intrinsics_block) > 0;
    if (free_intrinsics) {
      std_devs->intrinsics_by_noise[id] = marginal.StdDevs(intrinsics_block);
      std_devs->intrinsics_by_clusters[id] = marginal.ClusteredStdDevs(intrinsics_block);
      std_devs->intrinsics[id] =
          larger(std_devs->intrinsics_by_noise[id], std_devs->intrinsics_by_clusters[id]);
    }
    if (!housings_.count(id) || !marginal.offset.count(housings_.at(id).data())) continue;
    const double* housing_block = housings_.at(id).data();
    std_devs->housing_by_noise[id] = marginal.StdDevs(housing_block);
    std_devs->housing_by_clusters[id] = marginal.ClusteredStdDevs(housing_block);
    std_devs->housing[id] =
        larger(std_devs->housing_by_noise[id], std_devs->housing_by_clusters[id]);
    if (!free_intrinsics) continue;
    Eigen::MatrixXd& correlation = std_devs->intrinsics_housing_correlation[id];
    correlation.resize(marginal.size.at(intrinsics_block), marginal.size.at(housing_block));
    for (int i = 0; i < correlation.rows(); ++i) {
      for (int j = 0; j < correlation.cols(); ++j) {
        correlation(i, j) = marginal.Correlation(intrinsics_block, i, housing_block, j);
      }
    }
  }
}

}  // namespace portcal
