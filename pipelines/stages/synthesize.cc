#include "pipelines/stages/synthesize.h"

#include <chrono>
#include <filesystem>
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
#include "pipelines/synthetic/dataset_truth.h"
#include "pipelines/synthetic/frame_renderer.h"
#include "pipelines/synthetic/renderer.h"
#include "pipelines/synthetic/trajectory.h"

namespace fs = std::filesystem;

namespace portcal {

void SynthesizeOptions::Check() const {
  if (config_path.empty()) throw OptionError("--config", "''", "a dataset YAML file");
  if (output_path.empty()) throw OptionError("--output_path", "''", "an output directory");
  if (num_threads < 1) throw OptionError("--num_threads", num_threads, ">= 1");
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

// The ground truth, navigation and dot files next to the images, then the
// finished set moved into `output` (a failed run leaves it as it was).
void FinishSet(const SynthesizeOptions& options, const DatasetConfig& config, const Scene& scene,
               const GroundTruth& truth, const fs::path& staging, const fs::path& output) {
  WriteGroundTruth(truth, staging / "ground_truth.yaml", DatasetExtraYaml(config, scene));
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
  truth = DatasetTruthHeader(config, dir1, dir2);
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
