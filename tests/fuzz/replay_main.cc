// The fuzz targets in the ordinary build: a main that runs the target on
// every file of the corpus folders it is given, and on every prefix and a
// stride of one-byte changes of each (truncated and damaged files, the
// commonest bad input), without libFuzzer. workflows/fuzz.sh links the same
// targets with libFuzzer and the sanitizers for the long runs.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

void Run(const std::string& bytes) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

// The file, its prefixes and single-byte variants: about 200 inputs.
size_t RunVariants(const std::string& bytes) {
  size_t runs = 0;
  Run(bytes);
  ++runs;
  const size_t stride = std::max<size_t>(1, bytes.size() / 64);
  for (size_t cut = 0; cut < bytes.size(); cut += stride, ++runs) Run(bytes.substr(0, cut));
  for (size_t at = 0; at < bytes.size(); at += stride) {
    for (const char replacement : {'\0', '9', '-', '\n'}) {
      std::string changed = bytes;
      changed[at] = replacement;
      Run(changed);
      ++runs;
    }
  }
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  size_t files = 0, runs = 0;
  for (int i = 1; i < argc; ++i) {
    std::vector<std::filesystem::path> paths;
    if (!std::filesystem::exists(argv[i]))
      continue;  // no regressions yet: git keeps no empty folder
    if (std::filesystem::is_directory(argv[i])) {
      for (const auto& entry : std::filesystem::directory_iterator(argv[i]))
        paths.push_back(entry.path());
    } else {
      paths.emplace_back(argv[i]);
    }
    for (const std::filesystem::path& path : paths) {
      std::ifstream in(path, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
      runs += RunVariants(bytes);
      ++files;
    }
  }
  std::printf("%zu corpus files, %zu inputs, no crash\n", files, runs);
  return files > 0 ? 0 : 1;
}
