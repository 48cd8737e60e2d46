// What the fuzz targets share: the input as a file (portcal's parsers read
// paths, as users give them), the input split into the files of a model,
// and the input read as a stream of fields (for database rows).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "colmap_ext/util/error.h"

namespace portcal {
namespace fuzz {

// A folder of this process under TMPDIR (or /tmp), removed at exit.
inline const std::filesystem::path& WorkFolder() {
  static const std::filesystem::path folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path path =
        std::filesystem::path(tmp ? tmp : "/tmp") / ("portcal_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(WorkFolder(), ignored);
    });
    return path;
  }();
  return folder;
}

// `bytes` as the file WorkFolder()/name (rewritten each call).
inline std::filesystem::path WriteFile(const std::string& name, const std::string& bytes) {
  const std::filesystem::path path = WorkFolder() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

// Runs `parse` on the input written as the file `name`: InputError, which
// names the file, is the answer to bad bytes; anything else escapes (a
// finding).
template <typename Parse>
int ParseAsFile(const std::string& name, const uint8_t* data, size_t size, Parse&& parse);

// The input cut at each "\n--8<--\n" (how the seed corpus joins a model's
// files), at most `max_parts` parts, missing ones empty.
inline std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t max_parts) {
  static const std::string kCut = "\n--8<--\n";
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t start = 0;
  while (parts.size() + 1 < max_parts) {
    const size_t at = text.find(kCut, start);
    if (at == std::string::npos) break;
    parts.push_back(text.substr(start, at - start));
    start = at + kCut.size();
  }
  parts.push_back(text.substr(start));
  parts.resize(max_parts);
  return parts;
}

// Fields taken from the front of the input; zeros once it is used up.
class FieldReader {
 public:
  FieldReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  template <typename T>
  T Take() {
    T value{};
    const size_t n = std::min(sizeof(T), size_ - used_);
    if (n > 0) std::memcpy(&value, data_ + used_, n);
    used_ += n;
    return value;
  }
  // An integer in [low, high].
  int64_t TakeIn(int64_t low, int64_t high) {
    const uint64_t span = static_cast<uint64_t>(high - low) + 1;
    return low + static_cast<int64_t>(Take<uint32_t>() % span);
  }
  // Up to `max_size` bytes, the count taken first.
  std::string TakeBytes(size_t max_size) {
    const size_t n = std::min<size_t>(TakeIn(0, static_cast<int64_t>(max_size)), size_ - used_);
    std::string bytes(reinterpret_cast<const char*>(data_ + used_), n);
    used_ += n;
    return bytes;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t used_ = 0;
};

template <typename Parse>
int ParseAsFile(const std::string& name, const uint8_t* data, size_t size, Parse&& parse) {
  const std::filesystem::path path =
      WriteFile(name, std::string(reinterpret_cast<const char*>(data), size));
  try {
    parse(path);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace fuzz
}  // namespace portcal
