// Subcommands of the reconstruction back end: refractive_mapper,
// hierarchical_mapper, refractive_bundle_adjuster, auto_calibrator,
// calibration_subset_selector.
#include "colmap_ext/util/progress.h"
#include "pipelines/stages/auto_calibrator.h"
#include "pipelines/stages/calibration_subset_selector.h"
#include "pipelines/stages/hierarchical_mapper.h"
#include "pipelines/stages/refractive_bundle_adjuster.h"
#include "pipelines/stages/refractive_mapper.h"
#include "tools/command_line.h"
#include "tools/commands.h"
#include "tools/option_groups.h"

namespace portcal {

int CalibrationSubsetSelectorCommand(int argc, char** argv) {
  CalibrationSubsetSelectorOptions options;
  CommandLine cli("calibration_subset_selector",
                  "Chooses the images of a matched survey to self-calibrate the housing on: spread "
                  "evenly along "
                  "the acquisition order (name order), each sharing a verified pair with the one "
                  "before, so the "
                  "subset maps as one model. Writes them as a list for refractive_mapper "
                  "--image_list_path; map "
                  "and refine the subset refining the housing, then map every image with it held.");
  cli.AddRequired("database_path", &options.database_path, "matched database");
  cli.AddRequired("output_path", &options.output_path,
                  "the image list to write (one name per line)");
  cli.Add("Subset.num_images", &options.subset.num_images,
          "images to choose (more where the pairs fall short)");
  cli.Add("Subset.min_num_inliers", &options.subset.min_num_inliers,
          "verified inliers that link a chosen image to the one before");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunCalibrationSubsetSelector(options, progress);
  });
}

int RefractiveMapperCommand(int argc, char** argv) {
  RefractiveMapperOptions options;
  CommandLine cli(
      "refractive_mapper",
      "Incremental structure-from-motion on the verified matches in the database, every "
      "observation a ray in water behind the camera's housing (none: ordinary SfM). "
      "Writes COLMAP sparse models (+ housings.txt) into output_path/0, /1, ...");
  cli.AddRequired("database_path", &options.database_path, "database with verified matches");
  cli.Add("image_path", &options.image_path, "the images (accepted for COLMAP compatibility)");
  cli.AddRequired("output_path", &options.output_path, "directory for the models");
  cli.Add("image_list_path", &options.image_list_path,
          "file of image names, one per line: map only these and the pairs between them");
  cli.AddHousing(&options.housing, "the housing of all cameras (default: the database's)");
  cli.AddTriState(
      "Mapper.init_focal_from_markers", &options.init_focal_from_markers,
      "focal length from ArUco markers: -1 when the camera has no prior, 0 never, 1 always");
  cli.AddTriState("Mapper.init_focal_from_pairs", &options.init_focal_from_pairs,
                  "focal length from the verified pairs' epipolar geometry where the markers give "
                  "none: -1 when the camera has no prior, 0 never, 1 always");
  Register(&cli, &options.focal_start);
  cli.AddTriState("Mapper.init_radial_from_matches", &options.init_radial_from_matches,
                  "first radial distortion term from the verified matches: -1 when the camera has "
                  "no prior focal length "
                  "and no distortion and is not a fisheye, 0 never, 1 always");
  Register(&cli, &options.radial_start);
  Register(&cli, &options.mapper);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunRefractiveMapper(options, progress);
  });
}

int HierarchicalMapperCommand(int argc, char** argv) {
  HierarchicalMapperOptions options;
  CommandLine cli(
      "hierarchical_mapper",
      "refractive_mapper for large surveys: the scene graph cut into overlapping clusters (METIS), "
      "each "
      "mapped on its own (under mpirun or srun, shared out between the ranks), merged through the "
      "shared images and adjusted as a whole. Writes output_path/0 and each cluster's models under "
      "output_path/clusters/.");
  cli.AddRequired("database_path", &options.mapper.database_path, "database with verified matches");
  cli.Add("image_path", &options.mapper.image_path,
          "the images (accepted for COLMAP compatibility)");
  cli.AddRequired("output_path", &options.mapper.output_path, "directory for the models");
  cli.AddHousing(&options.mapper.housing, "the housing of all cameras (default: the database's)");
  cli.Add("Hierarchical.leaf_max_num_images", &options.partition.leaf_max_num_images,
          "images per cluster before the overlap");
  cli.Add("Hierarchical.image_overlap", &options.partition.image_overlap,
          "images each cluster takes from its neighbours");
  cli.Add("Hierarchical.min_shared_points", &options.merge.min_shared_points,
          "points a cluster's model must share with the merged ones to be merged");
  Register(&cli, &options.mapper.focal_start);
  Register(&cli, &options.mapper.radial_start);
  Register(&cli, &options.mapper.mapper);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunHierarchicalMapper(options, progress);
  });
}

int RefractiveBundleAdjusterCommand(int argc, char** argv) {
  RefractiveBundleAdjusterOptions options;
  CommandLine cli(
      "refractive_bundle_adjuster",
      "Bundle adjustment of a sparse model that self-calibrates the housing (flat: "
      "normal + distance; dome: decentering) and optionally the intrinsics, with "
      "standard deviations. --Markers.side_length (with --database_path) fixes the "
      "scale by the ArUco markers, --PosePrior.position_sigma by the images' position priors. "
      "Writes the model, calibration.yaml/.txt and report.html.");
  cli.AddRequired("input_path", &options.input_path, "sparse model (+ housings.txt)");
  cli.AddRequired("output_path", &options.output_path, "directory for the model and reports");
  cli.Add("database_path", &options.database_path,
          "database with marker detections or position priors (scale)");
  cli.AddHousing(&options.housing, "replaces the model's housings (first guess)");
  Register(&cli, &options.marker_scale);
  cli.Add("BundleAdjustment.max_reproj_error", &options.max_reproj_error_px,
          "observations beyond are dropped");
  cli.Add("BundleAdjustment.hold_weights", &options.hold_weights,
          "1: the first solve, robust, decides the inliers' weights and the final solve holds them "
          "(fast); "
          "0: both solves robust to function_tolerance");
  cli.Add("BundleAdjustment.robust_max_unsettled_weights", &options.robust_max_unsettled_weights,
          "with hold_weights: the first, robust solve also ends once a step changed at most this "
          "fraction of "
          "the weights by more than 0.01 (0: off)");
  cli.Add("BundleAdjustment.held_trust_region_radius", &options.held_trust_region_radius,
          "with hold_weights: the final solve's first trust region");
  cli.Add("BundleAdjustment.robust_function_tolerance", &options.robust_function_tolerance,
          "with hold_weights: relative cost change that ends the first, robust solve");
  cli.Add("BundleAdjustment.principal_point_test_sigmas", &options.principal_point_test_sigmas,
          "with refine_principal_point: hold it at the image centre unless it lies more sigmas "
          "than this from it (0: no test)");
  Register(&cli, &options.ba);
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
                  "mapper and refractive bundle adjustment in one run. Writes "
                  "calibration.yaml/.txt, report.html, "
                  "the sparse models and the database under --output_path.");
  cli.AddRequired("image_path", &options.image_path, "directory of images");
  cli.AddRequired("output_path", &options.output_path, "directory for the results");
  cli.Add("ImageReader.camera_model", &options.camera_model, "COLMAP camera model");
  cli.Add("ImageReader.camera_params", &options.camera_params, "known intrinsics (then held)");
  cli.AddHousing(&options.housing, "the housing to calibrate, with a first guess (none: in air)");
  cli.Add("Markers.dictionary", &options.marker_dictionary, kMarkersDictionaryHelp);
  Register(&cli, &options.marker_scale);
  cli.Add("Mask.enabled", &options.mask, "keep only features near markers (0 | 1)");
  cli.Add("Mask.enlargement_factor", &options.mask_enlargement_factor, kMaskEnlargementHelp);
  cli.AddChoice(
      "AutoCalibration.matcher", &options.matcher,
      {{"exhaustive", PairingMode::kExhaustive}, {"sequential", PairingMode::kSequential}},
      "pairs to match");
  cli.AddTriState("AutoCalibration.refine_intrinsics", &options.refine_intrinsics,
                  "-1: when --ImageReader.camera_params is empty; 0; 1");
  cli.AddTriState("AutoCalibration.refine_principal_point", &options.refine_principal_point,
                  "-1: with the intrinsics, held at the image centre unless the data move it "
                  "beyond 3 sigma; 0; 1");
  Register(&cli, &options.sift);
  cli.AddTriState("Mapper.init_focal_from_pairs", &options.init_focal_from_pairs,
                  "focal length from the verified pairs' epipolar geometry where the markers give "
                  "none: -1 when the intrinsics are refined, 0 never");
  cli.AddTriState("Mapper.init_radial_from_matches", &options.init_radial_from_matches,
                  "first radial distortion term from the verified matches before mapping: -1 when "
                  "the intrinsics are "
                  "refined and the model is not a fisheye, 0 never");
  cli.Add("AutoCalibration.max_num_starts", &options.max_num_starts,
          "map and refine again from the next random seed while a start fails or warns, at most "
          "this often");
  cli.Add("random_seed", &options.random_seed,
          "seed of every random choice (>= 0): same images, same calibration");
  cli.Add("update_database", &options.update_database,
          "write the calibrated camera and housing into output/database.db, for the next stage (0 "
          "| 1)");
  cli.Add("num_threads", &options.num_threads, "threads");
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunAutoCalibrator(options, progress);
  });
}

}  // namespace portcal
