// Subcommands of the reconstruction back end: refractive_mapper,
// refractive_bundle_adjuster, auto_calibrator.
#include "colmap_ext/util/progress.h"
#include "pipelines/stages/auto_calibrator.h"
#include "pipelines/stages/refractive_bundle_adjuster.h"
#include "pipelines/stages/refractive_mapper.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

static void AddMapperOptions(CommandLine* cli, IncrementalMapperOptions* o) {
  cli->Add("Mapper.init_min_num_inliers", &o->init_min_num_inliers, "inlier matches of the initial pair");
  cli->Add("Mapper.init_min_tri_angle", &o->init_min_tri_angle_deg, "median triangulation angle, degrees");
  cli->Add("Mapper.init_max_error", &o->init_max_error_px, "initial pair inlier threshold, pixels");
  cli->Add("Mapper.init_max_restarts", &o->init_max_restarts,
           "models started again from another initial pair when their intrinsics keep coming out implausible");
  cli->Add("Mapper.max_focal_ratio_to_start", &o->max_focal_ratio_to_start,
           "a focal length beyond this factor from the start is implausible (1.25 when the markers gave the start)");
  cli->Add("Mapper.init_scene_depth", &o->init_scene_depth_m,
           "scale when no marker size is given: median depth of the initial pair, metres");
  cli->Add("Mapper.abs_pose_max_error", &o->abs_pose_max_error_px, "registration threshold, pixels");
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
  cli->Add("Mapper.ba_global_images_ratio", &o->ba_global_images_ratio, "global adjustment when the model grows by");
  cli->Add("Mapper.ba_global_function_tolerance", &o->ba_global_function_tolerance,
           "a global adjustment ends when an iteration lowers the cost by less than this fraction");
  cli->Add("Mapper.ba_calibration_settled_px", &o->ba_calibration_settled_px,
           "hold intrinsics and housing until the final adjustment once two refinements in a row (from "
           "--Mapper.ba_calibration_settled_min_images on) moved the image by less than this, pixels (0: refine "
           "to the end)");
  cli->Add("Mapper.ba_calibration_settled_min_images", &o->ba_calibration_settled_min_images,
           "images a model needs before its calibration may be held");
  cli->Add("Mapper.multiple_models", &o->multiple_models, "0 | 1");
  cli->Add("Mapper.max_num_models", &o->max_num_models, "models at most");
  cli->Add("Mapper.min_model_size", &o->min_model_size, "images a model needs to be kept");
  cli->Add("Markers.side_length", &o->marker_scale.side_length_m,
           "ArUco marker side, metres: markers then fix the scale (0: off)");
  cli->Add("Markers.side_sigma", &o->marker_scale.sigma_m, "uncertainty of a marker side, metres");
  cli->Add("PosePrior.position_sigma", &o->position_prior_sigma_m,
           "position priors' uncertainty, metres (0: unused); global adjustments take the scale from them");
  cli->Add("random_seed", &o->random_seed, "seed of RANSAC's samples (>= 0): same input, same model");
  cli->Add("num_threads", &o->num_threads, "threads");
}

int RefractiveMapperCommand(int argc, char** argv) {
  RefractiveMapperOptions options;
  CommandLine cli("refractive_mapper",
                  "Incremental structure-from-motion on the verified matches in the database, every "
                  "observation a ray in water behind the camera's housing (none: ordinary SfM). "
                  "Writes COLMAP sparse models (+ housings.txt) into output_path/0, /1, ...");
  cli.AddRequired("database_path", &options.database_path, "database with verified matches");
  cli.Add("image_path", &options.image_path, "the images (accepted for COLMAP compatibility)");
  cli.AddRequired("output_path", &options.output_path, "directory for the models");
  cli.AddHousing(&options.housing, "the housing of all cameras (default: the database's)");
  cli.AddTriState("Mapper.init_focal_from_markers", &options.init_focal_from_markers,
          "focal length from ArUco markers: -1 when the camera has no prior, 0 never, 1 always");
  cli.AddTriState("Mapper.init_radial_from_matches", &options.init_radial_from_matches,
          "first radial distortion term from the verified matches: -1 when the camera has no prior focal length "
          "and no distortion and is not a fisheye, 0 never, 1 always");
  RadialStartOptions& radial = options.radial_start;
  cli.Add("Mapper.init_radial_min_k", &radial.min_k, "search range of the first radial term, lower end");
  cli.Add("Mapper.init_radial_max_k", &radial.max_k, "search range of the first radial term, upper end");
  cli.Add("Mapper.init_radial_num_steps", &radial.num_steps, "grid points over that range");
  cli.Add("Mapper.init_radial_max_num_pairs", &radial.max_num_pairs, "best-matched pairs used");
  cli.Add("Mapper.init_radial_max_matches", &radial.max_matches_per_pair, "matches used per pair");
  AddMapperOptions(&cli, &options.mapper);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunRefractiveMapper(options, progress);
  });
}

}  // namespace portcal

namespace portcal {

namespace {

void AddBundleOptions(CommandLine* cli, BundleAdjustmentOptions* ba) {
  cli->Add("BundleAdjustment.refine_housing", &ba->refine_housing, "flat: normal + distance; dome: centre (0 | 1)");
  cli->Add("BundleAdjustment.refine_focal_length", &ba->refine_focal_length, "0 | 1");
  cli->Add("BundleAdjustment.refine_principal_point", &ba->refine_principal_point, "0 | 1");
  cli->Add("BundleAdjustment.refine_extra_params", &ba->refine_extra_params, "0 | 1");
  cli->Add("BundleAdjustment.virtual_camera_error", &ba->virtual_camera_error,
           "virtual-camera error (1) or exact reprojection error (0)");
  cli->Add("BundleAdjustment.loss_scale", &ba->loss_scale, "Cauchy loss scale in pixels (0: none)");
  cli->Add("BundleAdjustment.max_num_iterations", &ba->max_num_iterations, "iterations");
  cli->Add("BundleAdjustment.function_tolerance", &ba->function_tolerance, "relative cost change that ends the solve");
  cli->Add("num_threads", &ba->num_threads, "threads");
}

}  // namespace

int RefractiveBundleAdjusterCommand(int argc, char** argv) {
  RefractiveBundleAdjusterOptions options;
  CommandLine cli("refractive_bundle_adjuster",
                  "Bundle adjustment of a sparse model that self-calibrates the housing (flat: "
                  "normal + distance; dome: decentering) and optionally the intrinsics, with "
                  "standard deviations. --Markers.side_length (with --database_path) fixes the "
                  "scale by the ArUco markers, --PosePrior.position_sigma by the images' position priors. Writes the model and calibration.yaml/.txt.");
  cli.AddRequired("input_path", &options.input_path, "sparse model (+ housings.txt)");
  cli.AddRequired("output_path", &options.output_path, "directory for the model and reports");
  cli.Add("database_path", &options.database_path, "database with marker detections or position priors (scale)");
  cli.AddHousing(&options.housing, "replaces the model's housings (first guess)");
  cli.Add("Markers.side_length", &options.marker_scale.side_length_m, "ArUco marker side, metres (0: no scale)");
  cli.Add("Markers.side_sigma", &options.marker_scale.sigma_m, "uncertainty of a marker side, metres");
  cli.Add("Markers.corner_sigma", &options.ba.marker_sigma_px, "uncertainty of a marker corner, px");
  cli.Add("BundleAdjustment.max_reproj_error", &options.max_reproj_error_px, "observations beyond are dropped");
  cli.Add("BundleAdjustment.principal_point_test_sigmas", &options.principal_point_test_sigmas,
          "with refine_principal_point: hold it at the image centre unless it lies more sigmas than this from it (0: no test)");
  cli.Add("PosePrior.position_sigma", &options.ba.position_prior_sigma_m,
          "position priors' uncertainty, metres (0: unused); they give the scale");
  AddBundleOptions(&cli, &options.ba);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunRefractiveBundleAdjuster(options, progress);
  });
}

int AutoCalibratorCommand(int argc, char** argv) {
  AutoCalibratorOptions options;
  CommandLine cli("auto_calibrator",
                  "Calibration without a known target: extract, mask (ArUco), match, refractive "
                  "mapper and refractive bundle adjustment in one run. Writes calibration.yaml/.txt, "
                  "the sparse models and the database under --output_path.");
  cli.AddRequired("image_path", &options.image_path, "directory of images");
  cli.AddRequired("output_path", &options.output_path, "directory for the results");
  cli.Add("ImageReader.camera_model", &options.camera_model, "COLMAP camera model");
  cli.Add("ImageReader.camera_params", &options.camera_params, "known intrinsics (then held)");
  cli.AddHousing(&options.housing, "the housing to calibrate, with a first guess (none: in air)");
  cli.Add("Markers.dictionary", &options.marker_dictionary, "ArUco dictionary");
  cli.Add("Markers.side_length", &options.marker_side_length_m, "marker side, metres: metric scale (0: none)");
  cli.Add("Mask.enabled", &options.mask, "keep only features near markers (0 | 1)");
  cli.Add("Mask.enlargement_factor", &options.mask_enlargement_factor, "marker quad scale");
  cli.AddChoice("AutoCalibration.matcher", &options.matcher,
                {{"exhaustive", PairingMode::kExhaustive}, {"sequential", PairingMode::kSequential}},
                "pairs to match");
  cli.AddTriState("AutoCalibration.refine_intrinsics", &options.refine_intrinsics,
          "-1: when --ImageReader.camera_params is empty; 0; 1");
  cli.AddTriState("AutoCalibration.refine_principal_point", &options.refine_principal_point,
          "-1: with the intrinsics, held at the image centre unless the data move it beyond 3 sigma; 0; 1");
  cli.Add("SiftExtraction.max_num_features", &options.sift.max_num_features, "per image");
  cli.Add("SiftExtraction.max_image_size", &options.sift.max_image_size, "pixels");
  cli.AddTriState("Mapper.init_radial_from_matches", &options.init_radial_from_matches,
          "first radial distortion term from the verified matches before mapping: -1 when the intrinsics are "
          "refined and the model is not a fisheye, 0 never");
  cli.Add("AutoCalibration.max_num_starts", &options.max_num_starts,
          "map and refine again from the next random seed while a start fails or warns, at most this often");
  cli.Add("random_seed", &options.random_seed, "seed of every random choice (>= 0): same images, same calibration");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunAutoCalibrator(options, progress);
  });
}

}  // namespace portcal
