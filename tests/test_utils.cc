#include "tests/test_utils.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace portcal {
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

}  // namespace testing
}  // namespace portcal
