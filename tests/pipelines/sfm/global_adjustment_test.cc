// The incremental mapper's global adjustments: what each refines at a
// model's size and how each ends. The growth-time adjustments that hold the
// calibration stop once the robust weights have settled, those that refine
// it converge, and the model's final pair is a robust solve that decides the
// weights followed by a weighted least-squares solve that holds them, with
// the refinement's first trust region (docs/scale.md); each ends on its own
// criterion or runs out of iterations.
#include "pipelines/sfm/global_adjustment.h"

#include <gtest/gtest.h>

#include "colmap_ext/camera/camera.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"
#include "pipelines/sfm/incremental_mapper.h"

namespace portcal {
namespace {

IncrementalMapperOptions HousingRefiningOptions() {
  IncrementalMapperOptions options;
  options.ba_refine_focal_length = true;
  options.ba_refine_extra_params = true;
  options.ba_refine_housing = true;
  options.ba_global_max_unsettled_weights = 0.02;
  options.ba_global_function_tolerance = 1e-7;
  options.ba_max_num_iterations = 40;
  return options;
}

// The stop of a robust solve that no settled-weights test ends.
void ExpectCostChangeStop(const BundleAdjustmentOptions& ba,
                          const IncrementalMapperOptions& options) {
  EXPECT_EQ(ba.max_unsettled_weight_fraction, 0);
  EXPECT_FALSE(ba.hold_loss_weights);
  EXPECT_EQ(ba.initial_trust_region_radius, BundleAdjustmentOptions().initial_trust_region_radius);
  EXPECT_EQ(ba.function_tolerance, options.ba_global_function_tolerance);
  EXPECT_EQ(ba.max_num_iterations, options.ba_max_num_iterations);
}

TEST(GlobalAdjustmentOptions, RefineWhatTheMapperSaysOnceTheModelIsLargeEnough) {
  const IncrementalMapperOptions options = HousingRefiningOptions();
  const BundleAdjustmentOptions small = GlobalAdjustmentOptions(options, 6, true);
  EXPECT_TRUE(small.refine_focal_length && small.refine_extra_params && small.refine_housing);
  EXPECT_FALSE(small.refine_principal_point);
  EXPECT_EQ(small.max_num_extra_params, 1);  // below ba_full_intrinsics_min_images
  const BundleAdjustmentOptions large =
      GlobalAdjustmentOptions(options, options.ba_full_intrinsics_min_images, true);
  EXPECT_EQ(large.max_num_extra_params, BundleAdjustmentOptions().max_num_extra_params);
  const BundleAdjustmentOptions held = GlobalAdjustmentOptions(options, 100, false);
  EXPECT_FALSE(held.refine_focal_length || held.refine_extra_params || held.refine_housing);
  ExpectCostChangeStop(held, options);
}

TEST(GlobalAdjustmentOptions, GrowthStopsAtSettledWeightsOnlyWithTheCalibrationHeld) {
  const IncrementalMapperOptions options = HousingRefiningOptions();
  const BundleAdjustmentOptions carrying =
      GlobalAdjustmentOptions(options, 100, false, AdjustmentEnd::kGrowing);
  EXPECT_EQ(carrying.max_unsettled_weight_fraction, options.ba_global_max_unsettled_weights);
  EXPECT_FALSE(carrying.hold_loss_weights);
  // One that refines the calibration decides whether the port has settled:
  // it converges.
  ExpectCostChangeStop(GlobalAdjustmentOptions(options, 100, true, AdjustmentEnd::kGrowing),
                       options);
  // 0 turns the settled-weights stop off.
  IncrementalMapperOptions off = options;
  off.ba_global_max_unsettled_weights = 0;
  ExpectCostChangeStop(GlobalAdjustmentOptions(off, 100, false, AdjustmentEnd::kGrowing), off);
}

TEST(GlobalAdjustmentOptions, FinalPairDecidesTheWeightsThenHoldsThem) {
  const IncrementalMapperOptions options = HousingRefiningOptions();
  const BundleAdjustmentOptions deciding =
      GlobalAdjustmentOptions(options, 100, true, AdjustmentEnd::kWeightsSettled);
  EXPECT_EQ(deciding.max_unsettled_weight_fraction, options.ba_global_max_unsettled_weights);
  EXPECT_FALSE(deciding.hold_loss_weights);
  EXPECT_TRUE(deciding.refine_housing);

  const BundleAdjustmentOptions held =
      GlobalAdjustmentOptions(options, 100, true, AdjustmentEnd::kHeldWeightsSolve);
  EXPECT_TRUE(held.hold_loss_weights);
  // With the weights held the settled-weights test would end the solve at
  // its first step.
  EXPECT_EQ(held.max_unsettled_weight_fraction, 0);
  EXPECT_EQ(held.initial_trust_region_radius, kHeldWeightsTrustRegionRadius);
  EXPECT_GT(held.initial_trust_region_radius,
            1e3 * BundleAdjustmentOptions().initial_trust_region_radius);
  EXPECT_TRUE(held.refine_housing && held.refine_focal_length);
  EXPECT_EQ(held.function_tolerance, options.ba_global_function_tolerance);
  EXPECT_NO_THROW(held.Check());
  // The refinement's held solve is the same but for its radius option.
  const BundleAdjustmentOptions refinement =
      deciding.WithWeightsHeld(kHeldWeightsTrustRegionRadius);
  EXPECT_EQ(refinement.hold_loss_weights, held.hold_loss_weights);
  EXPECT_EQ(refinement.max_unsettled_weight_fraction, held.max_unsettled_weight_fraction);
  EXPECT_EQ(refinement.initial_trust_region_radius, held.initial_trust_region_radius);
}

// The final robust solve ends once its weights settle (USER_SUCCESS, see
// RobustSolveEndsWhenTheWeightsSettle): that is its criterion, as the cost
// change is the others'; its refinement is measured and the port counts as
// converged. Only the iteration budget leaves an adjustment unfinished.
TEST(GlobalAdjustment, SettledWeightsEndAnAdjustmentAsConvergenceDoes) {
  ceres::Solver::Summary summary;
  summary.termination_type = ceres::CONVERGENCE;
  EXPECT_TRUE(EndedOnItsCriterion(summary));
  summary.termination_type = ceres::USER_SUCCESS;
  EXPECT_TRUE(EndedOnItsCriterion(summary));
  summary.termination_type = ceres::NO_CONVERGENCE;
  EXPECT_FALSE(EndedOnItsCriterion(summary));
}

// A focal length far from a guessed start is judged against what a lens
// could be; far from a start taken from the data, against the start.
TEST(GlobalAdjustment, AGuessedFocalLengthDoesNotJudgeTheAnswer) {
  const auto cameras_with_focal = [](double focal, double k1) {
    HousedCamera camera;
    camera.camera = Camera::FromModelName("RADIAL", focal, 1920, 1080);
    camera.camera.camera_id = 1;
    camera.camera.params[3] = k1;
    return std::map<camera_t, HousedCamera>{{1, camera}};
  };
  const auto start = cameras_with_focal(2304, 0);  // the image reader's 1.2 x width
  const auto wide = cameras_with_focal(1074, -0.2);
  EXPECT_TRUE(BogusIntrinsics(start, wide, start, 2.0, {}));  // 2.1 x from the start
  EXPECT_FALSE(BogusIntrinsics(start, wide, start, 2.0, {1}));
  // What no lens gives, or a distortion beyond COLMAP's bound, still is.
  EXPECT_TRUE(BogusIntrinsics(start, cameras_with_focal(250, 0), start, 2.0, {1}));
  EXPECT_TRUE(BogusIntrinsics(start, cameras_with_focal(12000, 0), start, 2.0, {1}));
  EXPECT_TRUE(BogusIntrinsics(start, cameras_with_focal(1074, 1.5), start, 2.0, {1}));
}

}  // namespace
}  // namespace portcal
