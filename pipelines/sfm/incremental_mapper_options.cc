#include "pipelines/sfm/incremental_mapper_options.h"

#include <string>

#include "colmap_ext/util/error.h"

namespace portcal {

void IncrementalMapperOptions::Check() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0)) throw OptionError(std::string("--Mapper.") + name, v, "> 0");
  };
  positive(init_min_num_inliers, "init_min_num_inliers");
  positive(init_max_error_px, "init_max_error");
  positive(init_scene_depth_m, "init_scene_depth");
  positive(abs_pose_max_error_px, "abs_pose_max_error");
  positive(filter_max_reproj_error_px, "filter_max_reproj_error");
  positive(ba_global_images_ratio, "ba_global_images_ratio");
  positive(max_num_models, "max_num_models");
  if (!(position_prior_sigma_m >= 0)) {
    throw OptionError("--PosePrior.position_sigma", position_prior_sigma_m, ">= 0 m");
  }
  const auto angle = [](double v, const char* name) {
    if (!(v >= 0 && v < 90)) {
      throw OptionError(std::string("--Mapper.") + name, v, "in [0, 90) degrees");
    }
  };
  angle(init_min_tri_angle_deg, "init_min_tri_angle");
  angle(filter_min_tri_angle_deg, "filter_min_tri_angle");
  angle(tri_min_angle_deg, "tri_min_angle");
  marker_scale.Check();
  if (abs_pose_min_num_inliers < 6) {
    throw OptionError("--Mapper.abs_pose_min_num_inliers", abs_pose_min_num_inliers, ">= 6");
  }
  if (!(max_focal_ratio_to_start > 1)) {
    throw OptionError("--Mapper.max_focal_ratio_to_start", max_focal_ratio_to_start, "> 1");
  }
  if (random_seed < 0) throw OptionError("--random_seed", random_seed, ">= 0");
  if (init_max_restarts < 0)
    throw OptionError("--Mapper.init_max_restarts", init_max_restarts, ">= 0");
  if (min_model_size < 2) throw OptionError("--Mapper.min_model_size", min_model_size, ">= 2");
  if (ba_local_num_images < 1) {
    throw OptionError("--Mapper.ba_local_num_images", ba_local_num_images, ">= 1");
  }
  if (!(ba_global_function_tolerance > 0 && ba_global_function_tolerance < 1)) {
    throw OptionError("--Mapper.ba_global_function_tolerance", ba_global_function_tolerance,
                      "in (0, 1)");
  }
  if (!(ba_global_max_unsettled_weights >= 0 && ba_global_max_unsettled_weights < 1)) {
    throw OptionError("--Mapper.ba_global_max_unsettled_weights", ba_global_max_unsettled_weights,
                      "in [0, 1)");
  }
  if (!(ba_calibration_settled_px >= 0)) {
    throw OptionError("--Mapper.ba_calibration_settled_px", ba_calibration_settled_px, ">= 0");
  }
  if (ba_full_intrinsics_min_images < 0) {
    throw OptionError("--Mapper.ba_full_intrinsics_min_images", ba_full_intrinsics_min_images,
                      ">= 0");
  }
  if (ba_calibration_settled_min_images < 2) {
    throw OptionError("--Mapper.ba_calibration_settled_min_images",
                      ba_calibration_settled_min_images, ">= 2");
  }
}

}  // namespace portcal
