#include "pipelines/synthetic/dataset_truth.h"

#include <iomanip>
#include <random>
#include <sstream>

namespace portcal {

GroundTruth DatasetTruthHeader(const DatasetConfig& config, const std::string& dir1,
                               const std::string& dir2) {
  GroundTruth truth;
  truth.name = config.name;
  truth.description = config.description;
  truth.seed = static_cast<int64_t>(config.seed);
  truth.camera = config.camera;
  truth.housing = config.housing;
  if (config.stereo) {
    truth.stereo = StereoTruth{config.cam2_from_cam1,
                               config.camera2,
                               config.housing2,
                               config.cam2_from_cam1.Inverse().translation.norm(),
                               {dir1, dir2}};
  }
  return truth;
}

std::string DatasetExtraYaml(const DatasetConfig& config, const Scene& scene) {
  const Clutter* clutter = scene.clutter ? &*scene.clutter : nullptr;
  const SurveyPath* survey = config.survey ? &scene.survey : nullptr;
  const std::vector<SeabedMarker>& markers = scene.seabed_markers.markers;
  std::ostringstream out;
  out.precision(17);
  if (clutter) {
    out << "clutter:\n  plane: z = " << config.clutter_distance_m
        << " in the rig (camera 1) frame, fronto-parallel, static\n  distance: "
        << config.clutter_distance_m << "\n  extent_xy:\n  - [" << clutter->extent[0] << ", "
        << clutter->extent[1] << "]\n  - [" << clutter->extent[2] << ", " << clutter->extent[3]
        << "]\n  texel: " << clutter->texel << "\n  seed: " << config.clutter_seed
        << "\n  num_shapes: " << config.clutter_num_shapes << "\n";
  } else {
    out << "clutter: null\n";
  }
  const ImageFormationOptions& r = config.render;
  out << "render:\n  spp: " << r.spp << "\n  sample_positions: stratum centres\n"
      << "  filter: box (mean of samples)\n  blur_sigma: " << r.blur_sigma_px
      << "\n  noise_sigma: " << r.noise_sigma << "\n  levels:\n    white: " << r.levels.white
      << "\n    black: " << r.levels.black << "\n    background: " << r.levels.background
      << "\n    invalid: " << r.levels.invalid << "\n    back: " << r.levels.back
      << "\n  water:\n    attenuation_per_m: " << r.attenuation_per_m
      << "\n    backscatter_gray: " << r.backscatter_gray
      << "\n    forward_scatter_per_m: " << r.forward_scatter_per_m
      << "\n    forward_scatter_sigma_px: " << r.forward_scatter_sigma_px
      << "\n  vignetting: " << r.vignetting << "\n  motion_blur:\n    velocity_m_s: ["
      << r.velocity_m_s.x() << ", " << r.velocity_m_s.y() << ", " << r.velocity_m_s.z()
      << "]\n    angular_velocity_rad_s: [" << r.angular_velocity_rad_s.x() << ", "
      << r.angular_velocity_rad_s.y() << ", " << r.angular_velocity_rad_s.z()
      << "]\n    exposure_s: " << r.exposure_s << "\n    samples: " << r.motion_samples
      << "\n  png: 8-bit grayscale\n";
  out << "occlusion:\n  probability: " << config.occlusion_probability
      << "\n  fraction: " << config.occlusion_fraction << "\n";
  if (survey) {
    const SurveyOptions& s = config.survey_options;
    out << "survey:\n  world_frame: seabed, z up; cam_from_target = cam_from_world\n"
        << "  height: " << s.height_m << "\n  speed: " << s.speed_m_s
        << "\n  frame_rate: " << s.frame_rate_hz << "\n  side_overlap: " << s.side_overlap
        << "\n  line_length: " << s.line_length_m << "\n  line_spacing: " << survey->line_spacing_m
        << "\n  frame_spacing: " << survey->frame_spacing_m
        << "\n  footprint_width: " << survey->footprint_width_m
        << "\n  roughness: " << s.roughness_m << "\n  relief_wavelength: " << s.relief_wavelength_m
        << "\n  texel: " << s.texel_m << "\n  seed: " << s.texture_seed << "\n";
    if (!markers.empty()) {
      out << "  markers:\n    dictionary: " << s.markers.dictionary
          << "\n    side: " << s.markers.side_m
          << "\n    corners:  # id: TL, TR, BR, BL in the world frame\n"
          << std::setprecision(9);
      for (const SeabedMarker& m : markers) {
        out << "      " << m.id << ": [";
        for (int k = 0; k < 4; ++k) {
          out << (k ? ", " : "") << "[" << m.corners[k].x() << ", " << m.corners[k].y() << ", "
              << m.corners[k].z() << "]";
        }
        out << "]\n";
      }
    }
  } else {
    const ViewSamplingOptions& p = config.poses;
    out << "pose_generation:\n  distance: [" << p.distance_min_m << ", " << p.distance_max_m
        << "]\n  tilt_max_deg: " << p.tilt_max_deg << "\n  roll_max_deg: " << p.roll_max_deg
        << "\n  border_margin_px: " << p.border_margin_px
        << "\n  max_view_angle_deg: " << p.max_view_angle_deg << "\n  visibility: " << p.visibility
        << "\n";
  }
  return out.str();
}

std::string NavigationText(const GroundTruth& truth, double sigma_m, uint64_t seed) {
  std::mt19937_64 rng(seed * 7919ULL + 17ULL);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::ostringstream out;
  out << "# NAME X Y Z: camera centres in the seabed frame (z up), metres, with noise of sigma "
      << sigma_m << " m per axis\n";
  out.precision(9);
  const auto line = [&](const std::string& file, const Rigid3d& cam_from_world) {
    const Eigen::Vector3d centre = cam_from_world.Inverse().translation;
    const std::string prefix = "images/";
    const std::string name = file.rfind(prefix, 0) == 0 ? file.substr(prefix.size()) : file;
    out << name;
    for (int k = 0; k < 3; ++k) out << " " << centre[k] + sigma_m * noise(rng);
    out << "\n";
  };
  for (const FrameTruth& frame : truth.images) {
    line(frame.cam1.file, frame.cam1.cam_from_target);
    if (frame.cam2) line(frame.cam2->file, frame.cam2->cam_from_target);
  }
  return out.str();
}

}  // namespace portcal
