// Subcommands of the reconstruction back end: refractive_mapper,
// refractive_bundle_adjuster, auto_calibrator.
#include "pipelines/refractive_mapper.h"
#include "tools/command_line.h"
#include "tools/commands.h"

namespace portcal {

void AddMapperOptions(CommandLine* cli, IncrementalMapperOptions* o) {
  cli->Add("Mapper.init_min_num_inliers", &o->init_min_num_inliers, "inlier matches of the initial pair");
  cli->Add("Mapper.init_min_tri_angle", &o->init_min_tri_angle_deg, "median triangulation angle, degrees");
  cli->Add("Mapper.init_max_error", &o->init_max_error_px, "initial pair inlier threshold, pixels");
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
  cli->Add("Mapper.ba_local_num_images", &o->ba_local_num_images, "images in a local adjustment");
  cli->Add("Mapper.ba_global_images_ratio", &o->ba_global_images_ratio, "global adjustment when the model grows by");
  cli->Add("Mapper.multiple_models", &o->multiple_models, "0 | 1");
  cli->Add("Mapper.max_num_models", &o->max_num_models, "models at most");
  cli->Add("Mapper.min_model_size", &o->min_model_size, "images a model needs to be kept");
  cli->Add("Markers.side_length", &o->marker_scale.side_length_m,
           "ArUco marker side, metres: markers then fix the scale (0: off)");
  cli->Add("Markers.side_sigma", &o->marker_scale.sigma_m, "uncertainty of a marker side, metres");
  cli->Add("num_threads", &o->num_threads, "threads");
}

int RunRefractiveMapper(int argc, char** argv) {
  RefractiveMapperOptions options;
  CommandLine cli("refractive_mapper",
                  "Incremental structure-from-motion on the verified matches in the database, every "
                  "observation a ray in water behind the camera's housing (none: ordinary SfM). "
                  "Writes COLMAP sparse models (+ housings.txt) into output_path/0, /1, ...");
  cli.AddRequired("database_path", &options.database_path, "database with verified matches");
  cli.Add("image_path", &options.image_path, "the images (accepted for COLMAP compatibility)");
  cli.AddRequired("output_path", &options.output_path, "directory for the models");
  cli.Add("Housing.model", &options.housing.model, "FLATPORT | DOMEPORT for all cameras (default: the database's)");
  cli.Add("Housing.params", &options.housing.params, "housing parameters in the model's order");
  cli.Add("Mapper.init_focal_from_markers", &options.init_focal_from_markers,
          "focal length from ArUco markers: -1 when the camera has no prior, 0 never, 1 always");
  AddMapperOptions(&cli, &options.mapper);
  return ReportErrors([&] {
    if (!cli.Parse(argc, argv)) return;
    StderrProgress progress;
    RunRefractiveMapper(options, progress);
  });
}

}  // namespace portcal
