// The options of incremental structure-from-motion on refracted rays
// (incremental_mapper.h: its steps; incremental_pipeline.h: when to take
// them), shared by the steps, the global adjustment and the pair search.
#pragma once

#include <set>

#include "colmap_ext/util/types.h"
#include "pipelines/bundle_adjustment/bundle_adjustment.h"

namespace portcal {

struct IncrementalMapperOptions {
  int init_min_num_inliers = 50;
  double init_min_tri_angle_deg = 4.0;  // median over the initial points
  int init_max_num_trials = 20;         // candidate initial pairs tried per model
  // A model whose intrinsics come out implausible at three refinements in a
  // row, or at the last one, grew from a wrong start (e.g. a low-parallax
  // pair on the wrong side of the bas-relief ambiguity;
  // docs/dev/auto_calibration_notes.md): it is started again from the next candidate
  // pair, at most this many times; with no pair left, the first start is
  // built to the end, its intrinsics held.
  int init_max_restarts = 2;
  // A focal length more than this factor from the start counts as
  // implausible too (COLMAP's bound, 2, against its prior). When the ArUco
  // markers gave the start, refractive_mapper tightens it to 1.25: a model
  // grown from a wrong pair can drift that far over many adjustments, none
  // of them a factor 2 (docs/dev/auto_calibration_notes.md).
  double max_focal_ratio_to_start = 2.0;
  // Cameras whose starting focal length is a guess (no prior, none from the
  // markers or the pairs): judged against what a lens could be instead
  // (BogusIntrinsics).
  std::set<camera_t> guessed_focal_cameras;
  double init_max_error_px = 4.0;
  // Pairs no model starts from: the auto-calibrator's next start excludes
  // the pair the previous start's model grew from, so that it takes another
  // path (with only another random seed, three starts grew three identical
  // wrong models from one pair; docs/dev/auto_calibration_notes.md).
  std::set<image_pair_t> init_excluded_pairs;
  // Scale of a model when markers do not give it: the initial pair's median
  // scene depth, metres.
  double init_scene_depth_m = 1.0;
  double abs_pose_max_error_px = 12.0;
  int abs_pose_min_num_inliers = 30;
  double filter_max_reproj_error_px = 4.0;
  double filter_min_tri_angle_deg = 1.5;
  double tri_min_angle_deg = 1.5;
  bool ba_refine_focal_length = true;
  bool ba_refine_principal_point = false;
  bool ba_refine_extra_params = true;
  // Self-calibrate the housing in the global adjustments that refine the
  // intrinsics, so that structure and port co-evolve (a model built under an
  // untilted guess absorbs the tilt into poses and points, and the final
  // refinement may not climb out). Wants a metric scale (markers): without
  // one the port distance wanders and models split.
  bool ba_refine_housing = false;
  // Below this many images, of the distortion only the first radial term
  // is refined (the other terms held; the principal point as asked): a
  // handful of views of a small target cannot tell eight intrinsics apart,
  // and freed together they leave the basin (docs/dev/auto_calibration_notes.md).
  // 0: all from the start.
  int ba_full_intrinsics_min_images = 10;
  int ba_local_num_images = 6;
  double ba_global_images_ratio = 1.1;
  int ba_max_num_iterations = 50;
  // A global adjustment ends when an iteration lowers the cost by less than
  // this fraction. The mapper's models are intermediate (the refinement
  // stage converges fully, at 1e-8), and iterating them further changed
  // nothing downstream but the time (docs/benchmarks.md).
  double ba_global_function_tolerance = 1e-5;
  // A global adjustment while the model grows, with the calibration held,
  // also ends once a step changed the robust loss's weight of at most this
  // fraction of the observations by more than 0.01 (weights_settled.h): its
  // model is intermediate, and on a long survey the robust solve otherwise
  // crawls along the strips for more iterations the longer they are
  // (docs/scale.md). Adjustments that refine the calibration end by the
  // cost change alone; the model's final ones: ba_final_hold_weights. 0:
  // the cost change alone everywhere.
  double ba_global_max_unsettled_weights = 0.01;
  // The model's final adjustment on the refinement's schedule: a robust
  // solve that ends once the weights have settled (as above), the outliers
  // filtered, then one solve with the weights held (BundleAdjustmentOptions::
  // hold_loss_weights), a weighted least-squares problem Gauss-Newton
  // converges in a few steps. The robust solve alone crawls to its stop:
  // with the Cauchy loss it converges only linearly (BundleAdjustmentOptions::
  // hold_loss_weights; the 120-image survey: 18 iterations against 3 + 2,
  // the same refined port; docs/scale.md). 0: both final solves robust, to
  // the cost change.
  bool ba_final_hold_weights = true;
  // The intrinsics and housing are refined whenever the model has grown by
  // a third, until two such refinements in a row, on models of 50 images or
  // more, moved no point at the scene's median depth by this many pixels;
  // then they are held until the model's final adjustment, which refines
  // them on all images. Each refinement costs the exact refraction on every
  // observation, and on a survey the mapper's estimate stops improving early
  // (docs/benchmarks.md). Below the keypoints' noise, the held calibration
  // bends no structure. 0: refine to the end.
  double ba_calibration_settled_px = 0.25;
  // Below this many images the calibration is refined whenever the model
  // has grown by a third, however little it moves: such adjustments take
  // seconds, and from a few dozen views the estimate still moves with each
  // image (the 25-view target sets).
  int ba_calibration_settled_min_images = 50;
  bool multiple_models = true;
  int max_num_models = 50;
  int min_model_size = 3;
  MarkerScale marker_scale;  // side_length_m > 0: markers fix the scale
  // > 0: global adjustments align the model to the images' position priors
  // and keep them as residuals of this sigma (metres): the scale of a
  // survey, so that ba_refine_housing can estimate the port distance.
  double position_prior_sigma_m = 0;
  int random_seed = 0;  // RANSAC's samples (colmap_ext/util/random_seed.h)
  int num_threads = 2;
  void Check() const;  // throws OptionError naming --Mapper.*
};

}  // namespace portcal
