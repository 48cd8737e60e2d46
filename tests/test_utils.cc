#include "tests/test_utils.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "colmap_ext/util/string_utils.h"

namespace fs = std::filesystem;

namespace portcal {

ProgressSink& NoProgress() {
  static NullProgress progress;  // stateless, so shared safely
  return progress;
}

std::optional<Housing> HousingFromText(const std::string& model, const std::string& params) {
  if (model.empty()) return std::nullopt;
  return Housing::FromName(model, ParseDoubleList(params, "housing"), "housing");
}
namespace testing {

TempDir::TempDir() {
  std::string pattern = (fs::temp_directory_path() / "portcal_test_XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

std::optional<fs::path> SharedDir() {
  if (const char* env = std::getenv("PORTCAL_SHARED_DIR")) {
    if (fs::is_directory(env)) return fs::path(env);
    return std::nullopt;
  }
  const fs::path dir = PORTCAL_DEFAULT_SHARED_DIR;
  if (fs::is_directory(dir / "datasets")) return dir;
  return std::nullopt;
}

std::string PortcalBinary() { return PORTCAL_BINARY_PATH; }
std::string ColmapBinary() { return PORTCAL_COLMAP_BINARY; }

CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) {
    result.output.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string ReadFileToString(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream out;
  out << file.rdbuf();
  return out.str();
}

const char* const kTwoFaceTargetYaml = R"(target:
  type: target3d
  num_faces: 2
  fold_angle_deg: 120
  face_width: 0.2
  face_height: 0.25
  aruco_dict: DICT_4X4_50
  marker_ids: [0, 1]
  marker_size: 0.06
  quiet_zone_modules: 1
  dots: {seed: 11, r_min: 0.0015, r_max: 0.009, coverage: 0.5, gray_min: 20, gray_max: 110, edge_margin: 0.004}
)";

const char* const kThreeFaceTargetYaml = R"(target:
  type: target3d
  num_faces: 3
  fold_angle_deg: 120
  face_width: 0.2
  face_height: 0.25
  aruco_dict: DICT_4X4_50
  marker_ids: [0, 1, 2]
  marker_size: 0.06
  quiet_zone_modules: 1
  dots: {seed: 11, r_min: 0.0015, r_max: 0.009, coverage: 0.5, gray_min: 20, gray_max: 110, edge_margin: 0.004}
)";

GroundTruth RenderSet(const TempDir& dir, const std::string& config_yaml) {
  std::ofstream(dir / "set.yaml") << config_yaml;
  // Through the command, so that the helpers need no layer above colmap_ext
  // (each test links only what it tests).
  const CommandResult render =
      RunCommand(PortcalBinary() + " synthesize --log_level warn --config '" +
                 (dir / "set.yaml").string() + "' --output_path '" + (dir / "set").string() + "'");
  if (render.exit_code != 0) {
    throw std::runtime_error("portcal synthesize failed (exit " + std::to_string(render.exit_code) +
                             "): " + render.output);
  }
  return ReadGroundTruth(dir / "set/ground_truth.yaml");
}

cv::Mat ClutteredScene(int width, int height, uint64_t seed) {
  cv::Mat scene(height, width, CV_8UC1, cv::Scalar(110));
  cv::RNG rng(seed);
  const int num_shapes = width * height / 1500;
  for (int i = 0; i < num_shapes; ++i) {
    const cv::Point centre(rng.uniform(0, width), rng.uniform(0, height));
    const cv::Scalar gray(rng.uniform(20, 240));
    switch (i % 3) {
      case 0:
        cv::rectangle(scene, cv::Rect(centre, cv::Size(rng.uniform(5, 120), rng.uniform(5, 80))),
                      gray, cv::FILLED);
        break;
      case 1:
        cv::ellipse(scene, centre, cv::Size(rng.uniform(5, 70), rng.uniform(5, 40)),
                    rng.uniform(0, 180), 0, 360, gray, cv::FILLED);
        break;
      default:
        cv::line(scene, centre, centre + cv::Point(rng.uniform(-150, 150), rng.uniform(-150, 150)),
                 gray, rng.uniform(1, 6));
    }
  }
  cv::GaussianBlur(scene, scene, cv::Size(), 1.0);
  return scene;
}

}  // namespace testing
}  // namespace portcal
