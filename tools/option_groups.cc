#include "tools/option_groups.h"

namespace portcal {

void Register(CommandLine* cli, ImageReaderOptions* reader) {
  cli->Add("ImageReader.camera_model", &reader->camera_model, "COLMAP camera model");
  cli->Add("ImageReader.single_camera", &reader->single_camera,
           "one camera for all images (0 | 1)");
  cli->Add("ImageReader.single_camera_per_folder", &reader->single_camera_per_folder,
           "one camera per sub-folder, e.g. a stereo rig's cam1/ and cam2/ (0 | 1)");
  cli->Add("ImageReader.camera_params", &reader->camera_params,
           "initial parameters in COLMAP's order (default: from the image size)");
  cli->Add(
      "ImageReader.overwrite", &reader->overwrite,
      "on a rerun, import again the cameras of images the database holds with other reader options "
      "(0: that is an error naming the difference)");
}

void Register(CommandLine* cli, SiftExtractionOptions* sift) {
  cli->Add("SiftExtraction.max_num_features", &sift->max_num_features,
           "strongest features kept per image");
  cli->Add("SiftExtraction.max_image_size", &sift->max_image_size,
           "larger images are downscaled, pixels");
  cli->Add("SiftExtraction.first_octave", &sift->first_octave, "-1: start at 2x upsampled");
  cli->Add("SiftExtraction.octave_resolution", &sift->octave_resolution, "scales per octave");
  cli->Add("SiftExtraction.peak_threshold", &sift->peak_threshold,
           "DoG peak threshold (COLMAP's units)");
  cli->Add("SiftExtraction.edge_threshold", &sift->edge_threshold, "edge response threshold");
}

void Register(CommandLine* cli, DescriptorMatchingOptions* matching) {
  cli->Add("SiftMatching.max_ratio", &matching->max_ratio, "Lowe's ratio test");
  cli->Add("SiftMatching.max_distance", &matching->max_distance, "max descriptor angle, radians");
  cli->Add("SiftMatching.cross_check", &matching->cross_check, "mutual matches only (0 | 1)");
  cli->Add("SiftMatching.max_num_matches", &matching->max_num_matches, "per pair");
  cli->Add("SiftMatching.method", &matching->method,
           "brute_force (exact) | kdtree (approximate, FLANN)");
  cli->Add("SiftMatching.kdtree_num_trees", &matching->kdtree_num_trees, "randomized k-d trees");
  cli->Add("SiftMatching.kdtree_num_checks", &matching->kdtree_num_checks,
           "leaves visited per query");
}

void Register(CommandLine* cli, TwoViewVerificationOptions* verification) {
  cli->Add("TwoViewGeometry.max_error", &verification->max_error, "RANSAC threshold, pixels");
  cli->Add("TwoViewGeometry.confidence", &verification->confidence, "RANSAC confidence");
  cli->Add("TwoViewGeometry.max_num_trials", &verification->max_num_trials, "RANSAC iterations");
  cli->Add("TwoViewGeometry.min_num_inliers", &verification->min_num_inliers, "per verified pair");
  cli->Add("TwoViewGeometry.min_inlier_ratio", &verification->min_inlier_ratio,
           "inliers / matches for a verified pair");
}

void Register(CommandLine* cli, SequentialPairingOptions* sequential) {
  cli->Add("SequentialMatching.overlap", &sequential->overlap, "next images matched");
  cli->Add("SequentialMatching.quadratic_overlap", &sequential->quadratic_overlap,
           "also the images 2^k ahead (0 | 1)");
  cli->Add("SequentialMatching.loop_detection", &sequential->loop_detection,
           "loop candidates by image retrieval (0 | 1)");
  cli->Add("SequentialMatching.loop_detection_period", &sequential->loop_detection_period,
           "every n-th image queries the index");
  cli->Add("SequentialMatching.loop_detection_num_images", &sequential->loop_detection_num_images,
           "most similar images matched per query");
  cli->Add("SequentialMatching.vocabulary_size", &sequential->vocabulary_size, "visual words");
}

void Register(CommandLine* cli, SpatialPairingOptions* spatial) {
  cli->Add("SpatialMatching.max_num_neighbors", &spatial->max_num_neighbors,
           "nearest images matched");
  cli->Add("SpatialMatching.max_distance", &spatial->max_distance_m, "metres between positions");
  cli->Add("SpatialMatching.ignore_z", &spatial->ignore_z, "horizontal distances only (0 | 1)");
}

void Register(CommandLine* cli, MarkerScale* marker_scale) {
  cli->Add("Markers.side_length", &marker_scale->side_length_m,
           "ArUco marker side, metres: the markers then fix the scale (0: they do not)");
  cli->Add("Markers.side_sigma", &marker_scale->sigma_m, "uncertainty of a marker side, metres");
}

void Register(CommandLine* cli, IncrementalMapperOptions* o) {
  cli->Add("Mapper.init_min_num_inliers", &o->init_min_num_inliers,
           "inlier matches of the initial pair");
  cli->Add("Mapper.init_min_tri_angle", &o->init_min_tri_angle_deg,
           "median triangulation angle, degrees");
  cli->Add("Mapper.init_max_error", &o->init_max_error_px, "initial pair inlier threshold, pixels");
  cli->Add("Mapper.init_max_restarts", &o->init_max_restarts,
           "models started again from another initial pair when their intrinsics keep coming out "
           "implausible");
  cli->Add("Mapper.max_focal_ratio_to_start", &o->max_focal_ratio_to_start,
           "a focal length beyond this factor from the start is implausible (1.25 when the markers "
           "gave the start)");
  cli->Add("Mapper.init_scene_depth", &o->init_scene_depth_m,
           "scale when no marker size is given: median depth of the initial pair, metres");
  cli->Add("Mapper.abs_pose_max_error", &o->abs_pose_max_error_px,
           "registration threshold, pixels");
  cli->Add("Mapper.abs_pose_min_num_inliers", &o->abs_pose_min_num_inliers, "registration inliers");
  cli->Add("Mapper.filter_max_reproj_error", &o->filter_max_reproj_error_px, "pixels");
  cli->Add("Mapper.filter_min_tri_angle", &o->filter_min_tri_angle_deg, "degrees");
  cli->Add("Mapper.tri_min_angle", &o->tri_min_angle_deg, "degrees");
  cli->Add("Mapper.ba_refine_focal_length", &o->ba_refine_focal_length, "0 | 1");
  cli->Add("Mapper.ba_refine_principal_point", &o->ba_refine_principal_point, "0 | 1");
  cli->Add("Mapper.ba_refine_extra_params", &o->ba_refine_extra_params, "0 | 1");
  cli->Add("Mapper.ba_refine_housing", &o->ba_refine_housing,
           "refine the housing with the intrinsics in global adjustments (0 | 1)");
  cli->Add("Mapper.ba_full_intrinsics_min_images", &o->ba_full_intrinsics_min_images,
           "below this many images refine only the focal length and the first radial term");
  cli->Add("Mapper.ba_local_num_images", &o->ba_local_num_images, "images in a local adjustment");
  cli->Add("Mapper.ba_global_images_ratio", &o->ba_global_images_ratio,
           "global adjustment when the model grows by");
  cli->Add("Mapper.ba_global_function_tolerance", &o->ba_global_function_tolerance,
           "a global adjustment ends when an iteration lowers the cost by less than this fraction");
  cli->Add("Mapper.ba_global_max_unsettled_weights", &o->ba_global_max_unsettled_weights,
           "a global adjustment while the model grows, calibration held, also ends once a step "
           "changed at most "
           "this fraction of the robust weights by more than 0.01 (0: by the cost change alone)");
  cli->Add("Mapper.ba_final_hold_weights", &o->ba_final_hold_weights,
           "the model's final adjustment: robust until the weights settle, then a solve with them "
           "held (0 | 1; "
           "0: robust to the cost change)");
  cli->Add(
      "Mapper.ba_calibration_settled_px", &o->ba_calibration_settled_px,
      "hold intrinsics and housing until the final adjustment once two refinements in a row (from "
      "--Mapper.ba_calibration_settled_min_images on) moved the image by less than this, pixels "
      "(0: refine "
      "to the end)");
  cli->Add("Mapper.ba_calibration_settled_min_images", &o->ba_calibration_settled_min_images,
           "images a model needs before its calibration may be held");
  cli->Add("Mapper.multiple_models", &o->multiple_models, "0 | 1");
  cli->Add("Mapper.max_num_models", &o->max_num_models, "models at most");
  cli->Add("Mapper.min_model_size", &o->min_model_size, "images a model needs to be kept");
  Register(cli, &o->marker_scale);
  cli->Add("PosePrior.position_sigma", &o->position_prior_sigma_m,
           "position priors' uncertainty, metres (0: unused); global adjustments take the scale "
           "from them");
  cli->Add("random_seed", &o->random_seed,
           "seed of RANSAC's samples (>= 0): same input, same model");
  cli->Add("num_threads", &o->num_threads, "threads");
}

void Register(CommandLine* cli, FocalStartOptions* focal) {
  cli->Add("Mapper.init_focal_min_factor", &focal->min_focal_factor,
           "search range of the focal length from the pairs, lower end, x the larger image side");
  cli->Add("Mapper.init_focal_max_factor", &focal->max_focal_factor,
           "search range of the focal length from the pairs, upper end, x the larger image side");
  cli->Add("Mapper.init_focal_num_steps", &focal->num_steps,
           "grid points over that range (log spaced)");
  cli->Add("Mapper.init_focal_max_num_pairs", &focal->max_num_pairs, "best-matched pairs used");
  cli->Add("Mapper.init_focal_max_matches", &focal->max_matches_per_pair, "matches used per pair");
  cli->Add("Mapper.init_focal_min_contrast", &focal->min_contrast,
           "the cost 30 % from its minimum must exceed it by this factor minus one, or the pairs "
           "do not tell the focal length");
}

void Register(CommandLine* cli, RadialStartOptions* radial) {
  cli->Add("Mapper.init_radial_min_k", &radial->min_k,
           "search range of the first radial term, lower end");
  cli->Add("Mapper.init_radial_max_k", &radial->max_k,
           "search range of the first radial term, upper end");
  cli->Add("Mapper.init_radial_num_steps", &radial->num_steps, "grid points over that range");
  cli->Add("Mapper.init_radial_max_num_pairs", &radial->max_num_pairs, "best-matched pairs used");
  cli->Add("Mapper.init_radial_max_matches", &radial->max_matches_per_pair,
           "matches used per pair");
}

void Register(CommandLine* cli, BundleAdjustmentOptions* ba) {
  cli->Add("BundleAdjustment.refine_housing", &ba->refine_housing,
           "flat: normal + distance; dome: centre (0 | 1)");
  cli->Add("BundleAdjustment.refine_focal_length", &ba->refine_focal_length, "0 | 1");
  cli->Add("BundleAdjustment.refine_principal_point", &ba->refine_principal_point, "0 | 1");
  cli->Add("BundleAdjustment.refine_extra_params", &ba->refine_extra_params, "0 | 1");
  cli->Add("BundleAdjustment.virtual_camera_error", &ba->virtual_camera_error,
           "virtual-camera error (1) or exact reprojection error (0)");
  cli->Add("BundleAdjustment.loss_scale", &ba->loss_scale,
           "Cauchy loss scale, in units of sigma (0: none)");
  cli->Add("BundleAdjustment.max_num_iterations", &ba->max_num_iterations, "iterations");
  cli->Add("BundleAdjustment.function_tolerance", &ba->function_tolerance,
           "relative cost change that ends the solve");
  cli->Add("Markers.corner_sigma", &ba->marker_sigma_px, "uncertainty of a marker corner, pixels");
  cli->Add("PosePrior.position_sigma", &ba->position_prior_sigma_m,
           "position priors' uncertainty, metres (0: unused); they give the scale");
  cli->Add("num_threads", &ba->num_threads, "threads");
}

void Register(CommandLine* cli, TargetDetectorOptions* target) {
  cli->Add("Target.type", &target->type, "chessboard | aruco_grid | charuco");
  cli->Add("Target.cols", &target->chessboard.cols, "inner corners per row");
  cli->Add("Target.rows", &target->chessboard.rows, "inner corners per column");
  cli->Add("Target.square_size", &target->square_size_m, "chessboard/ChArUco square side, metres");
  cli->Add("Target.dictionary", &target->markers.dictionary,
           "ArUco dictionary (aruco_grid, charuco)");
  cli->Add("Target.markers_x", &target->markers.markers_x, "aruco_grid: markers per row");
  cli->Add("Target.markers_y", &target->markers.markers_y, "aruco_grid: markers per column");
  cli->Add("Target.marker_size", &target->markers.marker_size_m, "marker side, metres");
  cli->Add("Target.marker_separation", &target->markers.marker_separation_m,
           "aruco_grid: gap, metres");
  cli->Add("Target.first_marker", &target->markers.first_marker,
           "aruco_grid: id of the first marker");
  cli->Add("Target.squares_x", &target->markers.squares_x, "charuco: squares per row");
  cli->Add("Target.squares_y", &target->markers.squares_y, "charuco: squares per column");
  cli->Add("Target.coarse_max_image_size", &target->chessboard.coarse_max_image_size,
           "coarse detection on images downscaled to this size (0: full size)");
  cli->Add("Target.min_x_corner_fraction", &target->chessboard.min_x_corner_fraction,
           "images with fewer grid junctions than this fraction of the board's are not searched "
           "(0: all are)");
  cli->Add("Target.min_refined_corners", &target->chessboard.min_refined_corners,
           "views with fewer refined corners are refused");
  cli->Add("Target.partial_views", &target->chessboard.partial_views,
           "chessboards cut by the image's border: keep the corners in view where their place on "
           "the board can be "
           "told (from where the seen grid ends)");
  cli->Add("Target.max_level_drift", &target->chessboard.refinement.max_level_drift,
           "chessboard corners are fitted again with the board's shading taken out where its "
           "levels drift by "
           "more than this fraction of the contrast across a corner's window (0: wherever they "
           "drift; < 0: never)");
}

}  // namespace portcal
