// What the live calibrator's tests (and others on the same board) share: a
// rendered hand-held trajectory of a 9 x 6 chessboard before a 640 x 480
// OPENCV camera, the options that calibrate it, and target_extractor for
// that board.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "pipelines/stages/live_calibrator.h"
#include "pipelines/stages/target_extractor.h"
#include "tests/test_utils.h"

namespace portcal::testing {

// `pauses` pauses of 1.2 s, moves of 1 s, at 10 fps.
inline std::string LiveTrajectoryYaml(int seed, int pauses, bool video) {
  return "name: live_trajectory\nseed: " + std::to_string(seed) + R"(
camera: {model: OPENCV, width: 640, height: 480, params: [505, 498, 326.5, 236.0, -0.21, 0.06, 0.0012, -0.0007]}
housing: null
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.03, margin: 0.015}
poses: {distance: [0.35, 0.8], tilt_max_deg: 45, roll_max_deg: 20, border_margin_px: 15}
render: {spp: 2, blur_sigma: 0.6, noise_sigma: 2.0}
trajectory: {fps: 10, pause_seconds: 1.2, move_seconds: 1.0, exposure: 0.03, pauses: )" +
         std::to_string(pauses) + ", video: " + (video ? "true" : "false") + "}\n";
}

// The same on a rig: camera 2 10 cm to the right, turned 4 deg towards
// camera 1's field, with a lens of its own.
inline std::string LiveStereoTrajectoryYaml(int seed, int pauses, bool video) {
  return LiveTrajectoryYaml(seed, pauses, video) +
         "stereo:\n"
         "  cam2_from_cam1: {rotation_axis_angle_deg: [0, 1, 0, 4], translation: [-0.1, 0.002, "
         "0.004]}\n"
         "  camera2: {model: OPENCV, width: 640, height: 480, params: [511, 506, 317.5, 243.0, "
         "-0.19, 0.05, "
         "-0.0009, 0.0011]}\n";
}

// Each pause's first and last frame, from the set's trajectory.yaml.
inline std::vector<std::pair<int, int>> TrajectoryPauses(
    const std::filesystem::path& trajectory_yaml) {
  std::vector<std::pair<int, int>> pauses;
  for (const YAML::Node& pause : YAML::LoadFile(trajectory_yaml.string())["pauses"]) {
    pauses.emplace_back(pause["first_frame"].as<int>(), pause["last_frame"].as<int>());
  }
  return pauses;
}

// target_extractor with the board above (OPENCV cameras; or another model
// and a board of `cols` x 6 corners of `square_size_m`): one camera for all
// images, or one per folder (a rig's cam1/ and cam2/).
inline void ExtractBoard(const std::filesystem::path& images, const std::filesystem::path& database,
                         bool camera_per_folder, const std::string& camera_model = "OPENCV",
                         int cols = 9, double square_size_m = 0.03) {
  TargetExtractorOptions extract;
  extract.database_path = database.string();
  extract.image_path = images.string();
  extract.reader.camera_model = camera_model;
  extract.reader.single_camera = !camera_per_folder;
  extract.reader.single_camera_per_folder = camera_per_folder;
  extract.chessboard.cols = cols;
  extract.chessboard.rows = 6;
  extract.square_size_m = square_size_m;
  RunTargetExtractor(extract, NoProgress());
}

// Headless, the board and camera above, guidance over the rendered range.
inline LiveCalibratorOptions LiveOptions(const TempDir& dir, const std::string& source) {
  LiveCalibratorOptions options;
  options.live.source.source = source;
  options.database_path = (dir / "live.db").string();
  options.image_path = (dir / "kept").string();
  options.output_path = (dir / "out").string();
  options.reader.camera_model = "OPENCV";
  options.live.detector.chessboard.cols = 9;
  options.live.detector.chessboard.rows = 6;
  options.live.detector.square_size_m = 0.03;
  options.live.estimator.guidance.distance_min_m = 0.35;
  options.live.estimator.guidance.distance_max_m = 0.8;
  options.live.estimator.guidance.num_candidates = 100;
  options.live.status_interval_s = 0;
  options.page.headless = true;
  return options;
}

}  // namespace portcal::testing
