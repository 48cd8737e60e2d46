// Shared helpers of the test suite: temporary directories, the shared data
// folder (skipped cleanly when absent), and running executables.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <string>

#include "colmap_ext/housing/housing.h"
#include "colmap_ext/io/ground_truth.h"
#include "colmap_ext/util/progress.h"

namespace portcal {

// A progress sink that drops everything, for the stages the tests run.
ProgressSink& NoProgress();
// A housing as the flags write it (model name, comma-separated parameters);
// none for an empty model.
std::optional<Housing> HousingFromText(const std::string& model, const std::string& params);
namespace testing {

// A fresh directory removed at scope exit.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// ../shared beside the project root (PORTCAL_SHARED_DIR overrides), or
// nullopt when absent.
std::optional<std::filesystem::path> SharedDir();

// The built portcal executable and the colmap binary ("" when not found).
std::string PortcalBinary();
std::string ColmapBinary();

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};
// Runs a shell command, capturing its output.
CommandResult RunCommand(const std::string& command);

std::string ReadFileToString(const std::filesystem::path& path);

// Random rectangles, ellipses and lines overlapping on gray, blurred by 1
// px, as the shared textured renders look: an image with many
// junction-like spots and no chessboard.
cv::Mat ClutteredScene(int width, int height, uint64_t seed);

// Renders the set `config_yaml` describes (synthesize's YAML) into
// dir/set and returns its ground truth (the images under dir/set).
GroundTruth RenderSet(const TempDir& dir, const std::string& config_yaml);

// The `target:` block of a synthesize config for the shared sets' 3-D
// target: two faces folded at 120 deg, dots, ArUco markers 0 and 1 of
// DICT_4X4_50, 0.06 m.
extern const char* const kTwoFaceTargetYaml;
// The same with a third face (markers 0, 1 and 2).
extern const char* const kThreeFaceTargetYaml;

}  // namespace testing
}  // namespace portcal

// Skips the test with a message when the shared data folder is absent.
#define PORTCAL_REQUIRE_SHARED(var)                                                \
  const auto var##_opt = ::portcal::testing::SharedDir();                          \
  if (!var##_opt) GTEST_SKIP() << "../shared is absent: shared-data test skipped"; \
  const std::filesystem::path var = *var##_opt

#define PORTCAL_REQUIRE_COLMAP(var)                           \
  const std::string var = ::portcal::testing::ColmapBinary(); \
  if (var.empty()) GTEST_SKIP() << "the colmap binary was not found: interop test skipped"
