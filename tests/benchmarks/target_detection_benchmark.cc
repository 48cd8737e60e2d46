// Chessboard detection on 1920 x 1080 frames, one thread: a rendered view
// of a 10 x 7 board (blur 0.8 px, noise 2) with the precise corner fit and
// with the quick one (cornerSubPix, for live views), and a cluttered frame
// without a board, which the X-junction count turns away; an ArUco grid and
// a ChArUco board, precise (OpenCV's markers, portcal's fits). The `corners`
// counter is the number found; `median_error_px` / `max_error_px` are the
// corners' errors against the renderer's truth. Goals (issue 24): a frame
// with a board in <= 40 ms quick, one without in <= 10 ms.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/memory.h"
#include "colmap_ext/util/progress.h"
#include "pipelines/detection/target_detector.h"
#include "pipelines/detection/target_pose.h"
#include "pipelines/markers/marker_board_detector.h"
#include "pipelines/stages/synthesize.h"
#include "pipelines/target/chessboard_detector.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

struct RenderedFrame {
  cv::Mat gray;
  ImageTruth truth;
};

// One rendered 1080p view of the target described by `target_yaml`.
RenderedFrame Render(const std::string& name, const std::string& target_yaml) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("portcal_bench_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "set.yaml") << R"(name: bench
seed: 3
num_images: 1
camera: {model: RADIAL, width: 1920, height: 1080, params: [1500.0, 957.0, 543.0, -0.05, 0.01]}
housing: null
)" << target_yaml << R"(
poses: {distance: [0.6, 0.8], tilt_max_deg: 30, roll_max_deg: 20}
render: {spp: 4, blur_sigma: 0.8, noise_sigma: 2.0}
)";
  SynthesizeOptions options;
  options.config_path = (dir / "set.yaml").string();
  options.output_path = (dir / "set").string();
  NullProgress progress;
  RunSynthesize(options, progress);
  const GroundTruth truth = ReadGroundTruth(dir / "set/ground_truth.yaml");
  RenderedFrame result;
  result.gray =
      cv::imread((dir / "set" / truth.images[0].cam1.file).string(), cv::IMREAD_GRAYSCALE);
  result.truth = truth.images[0].cam1;
  std::filesystem::remove_all(dir);
  return result;
}

const RenderedFrame& BoardFrame() {
  static const RenderedFrame frame =
      Render("chessboard",
             "target: {type: chessboard, cols: 10, rows: 7, square_size: 0.03, margin: 0.02}\n");
  return frame;
}

// How many points were found and their errors against the truth.
void ErrorCounters(std::vector<double> errors, benchmark::State& state) {
  std::sort(errors.begin(), errors.end());
  state.counters["corners"] = static_cast<double>(errors.size());
  state.counters["median_error_px"] = errors.empty() ? -1 : errors[errors.size() / 2];
  state.counters["max_error_px"] = errors.empty() ? -1 : errors.back();
}

void DetectBoard(benchmark::State& state, bool precise) {
  const RenderedFrame& frame = BoardFrame();
  ChessboardDetectionOptions options;
  options.precise_fit = precise;
  ChessboardDetection detection;
  for (auto _ : state) {
    detection = DetectChessboard(frame.gray, options);
    benchmark::DoNotOptimize(detection);
  }
  const auto& truth = frame.truth.corners_px;
  std::vector<double> errors;
  for (size_t i = 0; i < detection.corners.size(); ++i) {
    if (!detection.corners[i]) continue;
    // Either order of a board that looks the same turned by 180 degrees.
    errors.push_back(std::min((*detection.corners[i] - *truth[i]).norm(),
                              (*detection.corners[i] - *truth[truth.size() - 1 - i]).norm()));
  }
  ErrorCounters(errors, state);
}

void BM_BoardFramePreciseFit(benchmark::State& state) { DetectBoard(state, true); }
void BM_BoardFrameQuick(benchmark::State& state) { DetectBoard(state, false); }

void BM_FrameWithoutBoard(benchmark::State& state) {
  const cv::Mat scene = testing::ClutteredScene(1920, 1080, 11);
  ChessboardDetectionOptions options;
  options.precise_fit = false;
  bool found = false;
  for (auto _ : state) {
    found = DetectChessboard(scene, options).found;
    benchmark::DoNotOptimize(found);
  }
  state.counters["found"] = found;
}

// Marker boards: OpenCV's ArUco detection, then portcal's corners (precise:
// the pixel fits; quick: markers on the halved image, edge crossings,
// OpenCV's ChArUco interpolation).
MarkerBoardOptions MarkerOptions(const std::string& type, bool precise) {
  MarkerBoardOptions options;
  options.type = type;
  options.markers_x = 6;
  options.markers_y = 4;
  options.marker_size_m = type == "charuco" ? 0.022 : 0.04;
  options.marker_separation_m = 0.01;
  options.squares_x = 9;
  options.squares_y = 6;
  options.square_size_m = 0.03;
  options.precise_fit = precise;
  return options;
}

const RenderedFrame& MarkerFrame(const std::string& type) {
  static const RenderedFrame grid = Render("aruco_grid",
                                           "target: {type: aruco_grid, markers_x: 6, markers_y: 4, "
                                           "marker_size: 0.04, marker_separation: 0.01}\n");
  static const RenderedFrame board = Render("charuco",
                                            "target: {type: charuco, squares_x: 9, squares_y: 6, "
                                            "square_size: 0.03, marker_size: 0.022}\n");
  return type == "charuco" ? board : grid;
}

void DetectMarkers(benchmark::State& state, const std::string& type, bool precise) {
  const RenderedFrame& frame = MarkerFrame(type);
  const MarkerBoardOptions options = MarkerOptions(type, precise);
  MarkerBoardDetection detection;
  for (auto _ : state) {
    detection = DetectMarkerBoard(frame.gray, options);
    benchmark::DoNotOptimize(detection);
  }
  std::vector<double> errors;
  for (const BoardPoint& point : detection.points) {
    if (type == "charuco") {
      errors.push_back((point.xy - *frame.truth.corners_px[point.point_id]).norm());
      continue;
    }
    for (const auto& marker : frame.truth.markers) {
      if (marker.id == point.point_id / 4)
        errors.push_back((point.xy - marker.corners_px[point.point_id % 4]).norm());
    }
  }
  ErrorCounters(errors, state);
}

void MarkersWithoutBoard(benchmark::State& state, const std::string& type, bool precise) {
  const cv::Mat scene = testing::ClutteredScene(1920, 1080, 11);
  const MarkerBoardOptions options = MarkerOptions(type, precise);
  bool found = false;
  for (auto _ : state) {
    found = DetectMarkerBoard(scene, options).found;
    benchmark::DoNotOptimize(found);
  }
  state.counters["found"] = found;
}

void BM_ArucoGridFrame(benchmark::State& state) { DetectMarkers(state, "aruco_grid", true); }
void BM_ArucoGridFrameQuick(benchmark::State& state) { DetectMarkers(state, "aruco_grid", false); }
void BM_CharucoFrame(benchmark::State& state) { DetectMarkers(state, "charuco", true); }
void BM_CharucoFrameQuick(benchmark::State& state) { DetectMarkers(state, "charuco", false); }
void BM_FrameWithoutArucoGrid(benchmark::State& state) {
  MarkersWithoutBoard(state, "aruco_grid", true);
}
void BM_FrameWithoutArucoGridQuick(benchmark::State& state) {
  MarkersWithoutBoard(state, "aruco_grid", false);
}

// The live detector: every target type found quick, and its pose from
// the known camera, in one call each; the pose's error against the truth.
void LiveFrame(benchmark::State& state, const std::string& type) {
  TargetDetectorOptions options;
  options.type = type;
  options.square_size_m = 0.03;
  options.markers = MarkerOptions(type, false);
  options.precise_fit = false;
  const RenderedFrame& frame = type == "chessboard" ? BoardFrame() : MarkerFrame(type);
  HousedCamera camera;
  camera.camera = Camera::FromModelName("RADIAL", 1500, 1920, 1080);
  camera.camera.params = {1500.0, 957.0, 543.0, -0.05, 0.01};
  std::optional<TargetPose> pose;
  for (auto _ : state) {
    pose = EstimateTargetPose(DetectTarget(frame.gray, options), camera);
    benchmark::DoNotOptimize(pose);
  }
  if (!pose) {
    state.SkipWithError("no pose");
    return;
  }
  const Rigid3d& truth = frame.truth.cam_from_target;
  state.counters["position_error_mm"] =
      1e3 * (pose->cam_from_target.translation - truth.translation).norm();
  state.counters["rotation_error_deg"] =
      pose->cam_from_target.rotation.angularDistance(truth.rotation) * 180 / M_PI;
  state.counters["rms_px"] = pose->rms_px;
}

void BM_LiveFrameChessboard(benchmark::State& state) { LiveFrame(state, "chessboard"); }
void BM_LiveFrameArucoGrid(benchmark::State& state) { LiveFrame(state, "aruco_grid"); }
void BM_LiveFrameCharuco(benchmark::State& state) { LiveFrame(state, "charuco"); }

BENCHMARK(BM_BoardFramePreciseFit)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BoardFrameQuick)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameWithoutBoard)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArucoGridFrame)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArucoGridFrameQuick)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CharucoFrame)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CharucoFrameQuick)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameWithoutArucoGrid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FrameWithoutArucoGridQuick)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LiveFrameChessboard)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LiveFrameArucoGrid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LiveFrameCharuco)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace portcal

int main(int argc, char** argv) {
  // As the portcal binary runs (colmap_ext/util/memory.h).
  portcal::KeepImageBuffersInTheHeap();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
