// The problem builder behind AdjustBundle (bundle_adjustment.h): the
// residuals (observations, marker constraints, position priors), the gauge,
// what the calibration blocks refine, the solver's choice, the standard
// deviations (bundle_problem_std_devs.cc) and the write-back, each a
// method. Internal to bundle_adjustment/.
#pragma once

#include <ceres/ceres.h>

#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "colmap_ext/geometry/pose_block.h"
#include "colmap_ext/util/error.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/bundle_adjustment/bundle_costs.h"
#include "pipelines/bundle_adjustment/calibration_covariance.h"

namespace portcal {

// A residual's robust weight w, held: rho(s) = w s (a ScaledLoss without
// an inner loss), kept by the problem builder in bulk.
class HeldWeight final : public ceres::LossFunction {
 public:
  explicit HeldWeight(double weight) : weight_(weight) {}
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = weight_ * s;
    rho[1] = weight_;
    rho[2] = 0;
  }

 private:
  double weight_;
};

// The problem owns the cost functions; the losses are the builder's (see
// BundleProblem's members).
ceres::Problem::Options ProblemOptions();

class BundleProblem {
 public:
  BundleProblem(Reconstruction* reconstruction, const BundleAdjustmentOptions& options,
                const BundleAdjustmentScope& scope, std::vector<MarkerCorner>* markers,
                const MarkerScale& marker_scale)
      : reconstruction_(reconstruction),
        options_(options),
        scope_(scope),
        markers_(markers),
        marker_scale_(marker_scale),
        poses_(reconstruction->mutable_poses()),
        cameras_(reconstruction->mutable_cameras()) {
    PORTCAL_CHECK(poses_.size() >= 2);
    for (const auto& [id, pose] : poses_) pose_blocks_[id] = ToPose(pose);
    for (auto& [id, camera] : cameras_) {
      intrinsics_[id] = camera.camera.params;
      if (camera.housing) housings_[id] = camera.housing->params;
    }
    // One loss object shared by the residuals. With the weights held, each
    // residual gets its own weight instead and the robust loss only
    // computes them.
    if (options.loss_scale > 0 && options.hold_loss_weights) {
      weight_loss_ = std::make_unique<ceres::CauchyLoss>(options.loss_scale);
    } else if (options.loss_scale > 0) {
      loss_ = std::make_unique<ceres::CauchyLoss>(options.loss_scale);
    }
    local_ = !scope.variable_images.empty();
    // Which blocks the residuals carry: constants are captured instead (see
    // bundle_costs.h), which makes the autodiff Jets much narrower.
    refine_intrinsics_ = !local_ && (options.refine_focal_length ||
                                     options.refine_principal_point || options.refine_extra_params);
    refine_housing_ = !local_ && options.refine_housing;
  }

  void AddPoints();
  void AddMarkers();
  void AddPositionPriors();
  void SetGauge();
  void SetCalibrationBlocks();
  ceres::Solver::Summary Solve();
  void ComputeStdDevs(const ceres::Solver::Summary& summary, CalibrationStdDevs* std_devs);
  void WriteBack();

 private:
  bool IsVariable(image_t id) const { return !local_ || scope_.variable_images.count(id) > 0; }
  CostBlocks BlocksOf(const HousedCamera& camera) const;
  void AddObservation(image_t image_id, const Eigen::Vector2d& pixel, double* xyz, double sigma);
  void AddRobustResidual(ceres::CostFunction* cost, const std::vector<double*>& blocks);
  double SigmaOf(const TrackElement& e) const;
  bool FreePose(image_t id) const;
  ceres::Solver::Options SolverOptions(int* num_free_poses) const;
  std::string Describe(const double* block, int index) const;
  std::string DescribeResidual(const std::vector<double*>& blocks) const;
  void StoreStdDevs(const MarginalCovariance& marginal, CalibrationStdDevs* std_devs) const;

  Reconstruction* reconstruction_;
  const BundleAdjustmentOptions& options_;
  const BundleAdjustmentScope& scope_;
  std::vector<MarkerCorner>* markers_;
  const MarkerScale& marker_scale_;
  std::map<image_t, Rigid3d>& poses_;
  std::map<camera_t, HousedCamera>& cameras_;
  std::map<image_t, PoseBlock> pose_blocks_;
  std::map<camera_t, std::vector<double>> intrinsics_, housings_;
  std::map<point3D_t, Eigen::Vector3d> point_blocks_;
  std::set<camera_t> used_cameras_;
  // The losses outlive the problem, which does not own them. A held weight
  // is 16 bytes here; as a ScaledLoss owned by the problem it was an
  // allocation and an entry in Ceres' table of the losses it owns, several
  // times that per observation (docs/scale.md).
  std::unique_ptr<ceres::LossFunction> loss_;  // the robust loss, shared
  std::unique_ptr<ceres::LossFunction>
      weight_loss_;                      // with hold_loss_weights: the weights' robust loss
  std::deque<HeldWeight> held_weights_;  // with hold_loss_weights: one per residual block
  ceres::HuberLoss prior_loss_{3.0};     // position priors' (3 sigma)
  ceres::Problem problem_{ProblemOptions()};
  std::vector<ceres::ResidualBlockId>
      robust_blocks_;  // under loss_, with max_unsettled_weight_fraction
  bool local_ = false;
  bool refine_intrinsics_ = false;
  bool refine_housing_ = false;
  bool use_markers_ = false;
  bool use_priors_ = false;
  int64_t num_residuals_ = 0;
};

}  // namespace portcal
