#include "pipelines/stages/synthesize.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <sstream>

#include "colmap_ext/camera/housed_camera.h"
#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/io/sparse_model.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"
#include "colmap_ext/util/new_paths.h"
#include "pipelines/synthetic/dataset_config.h"
#include "pipelines/synthetic/dataset_scene.h"
#include "pipelines/synthetic/frame_renderer.h"
#include "pipelines/synthetic/renderer.h"
#include "pipelines/synthetic/trajectory.h"

namespace fs = std::filesystem;

namespace portcal {

void SynthesizeOptions::Check() const {
  if (config_path.empty()) throw OptionError("--config", "''", "a dataset YAML file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  if (num_threads < 1) throw OptionError("--num_threads", std::to_string(num_threads), ">= 1");
}

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::string ImageName(int frame, int num_images) {
  std::ostringstream name;
  const int digits = std::max(3, static_cast<int>(std::to_string(num_images).size()));
  name << "img_" << std::setw(digits) << std::setfill('0') << frame + 1 << ".png";
  return name.str();
}

std::string ExtraYaml(const DatasetConfig& config, const Clutter* clutter, const SurveyPath* survey,
                      const std::vector<SeabedMarker>& markers) {
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

// A survey's navigation: each image's camera centre plus Gaussian noise per
// axis, as pose_prior_importer reads it (names relative to images/).
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

void WriteImage(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw InputError(path.string() + ": cannot write image");
}

// Renders frame `frame` and writes its images into the staging folder.
RenderedFrame RenderAndWrite(const FrameRenderer& renderer, const fs::path& staging, int frame,
                             const Rigid3d& cam_from_target, const ImageFormationOptions& render,
                             std::mt19937_64* rng) {
  const std::string name = ImageName(frame, renderer.config.num_images);
  RenderedFrame rendered = renderer.Render(frame, name, cam_from_target, render, rng);
  WriteImage(staging / renderer.dir1 / name, rendered.image1);
  if (!rendered.image2.empty()) WriteImage(staging / renderer.dir2 / name, rendered.image2);
  return rendered;
}

// The set's ground truth before any frame: names, cameras, housings, rig.
GroundTruth TruthHeader(const DatasetConfig& config, const std::string& dir1,
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

// The ground truth, navigation and dot files next to the images, then the
// finished set moved into `output` (a failed run leaves it as it was).
void FinishSet(const SynthesizeOptions& options, const DatasetConfig& config, const Scene& scene,
               const GroundTruth& truth, const fs::path& staging, const fs::path& output) {
  WriteGroundTruth(
      truth, staging / "ground_truth.yaml",
      ExtraYaml(config, scene.clutter ? &*scene.clutter : nullptr,
                config.survey ? &scene.survey : nullptr, scene.seabed_markers.markers));
  if (config.survey) {
    const std::string navigation =
        NavigationText(truth, config.survey_options.navigation_sigma_m, config.seed);
    WriteFileAtomically(staging / "navigation.txt", false,
                        [&](std::ostream& out) { out << navigation; });
  }
  if (!config.survey && config.target.type == "target3d") {
    const std::string csv = DotsCsv(scene.target.dots);
    WriteFileAtomically(staging / "target_dots.csv", false, [&](std::ostream& out) { out << csv; });
  }
  fs::copy_file(options.config_path, staging / "config_used.yaml",
                fs::copy_options::overwrite_existing);
  // The last moment to honour a stop; after it the output is replaced.
  if (CancelFlag::Requested()) throw Cancelled("nothing was written to " + options.output_path);
  for (const char* entry :
       {"images", "ground_truth.yaml", "target_dots.csv", "config_used.yaml", "navigation.txt",
        "trajectory.yaml", "trajectory.avi", "trajectory_cam2.avi"}) {
    if (!fs::exists(staging / entry)) continue;
    fs::remove_all(output / entry);
    fs::rename(staging / entry, output / entry);
  }
  fs::remove_all(staging);
}

// A trajectory's frames (its key poses sampled as independent views are),
// which then set the number of images; empty without a trajectory.
std::vector<TrajectoryFrame> PlanFrames(const Scene& scene, const HousedCamera& camera1,
                                        const HousedCamera& camera2, std::mt19937_64* rng,
                                        DatasetConfig* config) {
  if (!config->trajectory) return {};
  const std::vector<Eigen::Vector3d>& check_points = config->poses.visibility == "markers"
                                                         ? scene.target.marker_points
                                                         : scene.target.outline_points;
  std::vector<Rigid3d> key_poses;
  for (int k = 0; k < config->trajectory->num_pauses; ++k) {
    key_poses.push_back(SampleRigView(*config, scene, camera1, camera2, check_points, rng));
  }
  std::vector<TrajectoryFrame> frames = PlanTrajectory(key_poses, *config->trajectory);
  config->num_images = static_cast<int>(frames.size());
  return frames;
}

void OpenVideo(const fs::path& path, const Camera& camera, double fps, cv::VideoWriter* video) {
  video->open(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
              cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)), false);
  if (!video->isOpened())
    throw InputError(path.string() + ": OpenCV cannot write a Motion JPEG video here");
}

// Renders a trajectory's frames (motion blur while the target moves), and
// with `trajectory.video` the same frames as trajectory.avi (Motion JPEG, the
// codec OpenCV writes without FFmpeg); trajectory.yaml says where the pauses
// are.
void RenderTrajectory(const DatasetConfig& config, const FrameRenderer& renderer,
                      const std::vector<TrajectoryFrame>& frames, const fs::path& staging,
                      std::mt19937_64* rng, GroundTruth* truth, ProgressSink& progress) {
  const TrajectoryOptions& options = *config.trajectory;
  cv::VideoWriter video, video2;
  if (options.video) {
    OpenVideo(staging / "trajectory.avi", config.camera, options.fps, &video);
    if (config.stereo)
      OpenVideo(staging / "trajectory_cam2.avi", config.camera2, options.fps, &video2);
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    CancelFlag::ThrowIfRequested();
    ImageFormationOptions render = config.render;
    render.velocity_m_s = frames[f].velocity_m_s;
    render.angular_velocity_rad_s = frames[f].angular_velocity_rad_s;
    render.exposure_s = frames[f].pause < 0 ? options.exposure_s : 0.0;
    RenderedFrame rendered = RenderAndWrite(renderer, staging, static_cast<int>(f),
                                            frames[f].cam_from_target, render, rng);
    truth->images.push_back(std::move(rendered.truth));
    if (video.isOpened()) video.write(rendered.image1);
    if (video2.isOpened()) video2.write(rendered.image2);
    progress.Advance(1);
  }
  video.release();
  video2.release();
  const std::string yaml = TrajectoryYaml(frames, options);
  WriteFileAtomically(staging / "trajectory.yaml", false, [&](std::ostream& out) { out << yaml; });
}

}  // namespace

// The run itself; RunSynthesize names what a stop leaves.
static SynthesizeSummary Run(const SynthesizeOptions& options, ProgressSink& progress) {
  options.Check();
  const auto start = Clock::now();
  DatasetConfig config = ReadDatasetConfig(options.config_path);
  if (options.seed >= 0) config.seed = static_cast<uint64_t>(options.seed);
  config.render.num_threads = options.num_threads;
  const HousedCamera camera1{config.camera, config.housing},
      camera2{config.camera2, config.housing2};
  std::mt19937_64 rng(config.seed);
  GroundTruth truth;
  const Scene scene = BuildScene(config, camera1, &truth);
  const std::vector<TrajectoryFrame> trajectory =
      PlanFrames(scene, camera1, camera2, &rng, &config);
  LOG(INFO) << "synthesize: " << config.name << ", " << config.num_images << " frames of "
            << config.camera.width << "x" << config.camera.height
            << (config.stereo ? " (stereo)" : "") << ", "
            << (config.survey ? "survey" : config.target.type);

  const fs::path output(options.output_path);
  const fs::path staging = output / ".synthesize_staging";
  fs::remove_all(staging);
  // A failed render leaves no staging folder, nor an output folder that
  // was not there.
  NewPaths new_paths({output, staging});
  fs::create_directories(staging / "images");
  const std::string dir1 = config.stereo ? "images/cam1" : "images";
  const std::string dir2 = "images/cam2";
  fs::create_directories(staging / dir1);
  if (config.stereo) fs::create_directories(staging / dir2);

  const TargetDescription target = truth.target;
  truth = TruthHeader(config, dir1, dir2);
  truth.target = target;

  const auto ray_start = Clock::now();
  const RayMap rays1(config.camera, camera1.HousingOrNull(), config.render.spp,
                     options.num_threads);
  std::optional<RayMap> rays2;
  if (config.stereo)
    rays2.emplace(config.camera2, camera2.HousingOrNull(), config.render.spp, options.num_threads);
  const double ray_seconds = Seconds(ray_start);

  progress.Begin("synthesize: frames", config.num_images);
  const auto render_start = Clock::now();
  const FrameRenderer renderer{config, scene, camera1, camera2, rays1, rays2, dir1, dir2};
  if (trajectory.empty()) {
    const std::vector<Eigen::Vector3d>& check_points = config.poses.visibility == "markers"
                                                           ? scene.target.marker_points
                                                           : scene.target.outline_points;
    for (int frame = 0; frame < config.num_images; ++frame) {
      CancelFlag::ThrowIfRequested();
      Rigid3d cam_from_target;
      try {
        cam_from_target = config.survey
                              ? scene.survey.cam_from_world[frame]
                              : SampleRigView(config, scene, camera1, camera2, check_points, &rng);
      } catch (const NumericalError& e) {
        throw NumericalError(options.config_path + ": " +
                             e.what());  // the config asks what cannot be
      }
      truth.images.push_back(
          RenderAndWrite(renderer, staging, frame, cam_from_target, config.render, &rng).truth);
      progress.Advance(1);
    }
  } else {
    RenderTrajectory(config, renderer, trajectory, staging, &rng, &truth, progress);
  }
  progress.End();
  const double render_seconds = Seconds(render_start);
  FinishSet(options, config, scene, truth, staging, output);
  new_paths.Keep();

  SynthesizeSummary summary;
  summary.num_images = config.num_images;
  summary.seconds = Seconds(start);
  summary.ray_seconds = ray_seconds;
  summary.render_seconds_per_image = render_seconds / (config.num_images * (config.stereo ? 2 : 1));
  LOG(INFO) << "synthesize: " << summary.num_images << " frames in " << summary.seconds
            << " s (rays " << ray_seconds << " s once, " << summary.render_seconds_per_image
            << " s per image) -> " << output.string();
  return summary;
}

SynthesizeSummary RunSynthesize(const SynthesizeOptions& options, ProgressSink& progress) {
  try {
    return Run(options, progress);
  } catch (const Cancelled&) {
    throw Cancelled("nothing was written to " + options.output_path);  // not "the database"
  }
}

}  // namespace portcal
