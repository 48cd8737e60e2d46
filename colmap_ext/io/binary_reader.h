// Little-endian binary model files (COLMAP's .bin): reading with every
// read checked and counts guarded before allocating; writing a value.
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "colmap_ext/util/error.h"

namespace portcal {

class BinaryReader {
 public:
  explicit BinaryReader(const std::filesystem::path& path)
      : path_(path), file_(path, std::ios::binary) {
    if (!file_) throw InputError(path.string() + ": cannot open");
  }

  template <typename T>
  T Read(const char* what) {
    T value;
    file_.read(reinterpret_cast<char*>(&value), sizeof(T));
    if (!file_) {
      throw InputError(path_.string() + ": truncated file while reading " + what);
    }
    return value;
  }

  double ReadFinite(const char* what) {
    const double value = Read<double>(what);
    if (!std::isfinite(value)) {
      throw InputError(path_.string() + ": non-finite " + what);
    }
    return value;
  }

  std::string ReadName() {
    std::string name;
    char c;
    while (true) {
      c = Read<char>("image name");
      if (c == '\0') break;
      name.push_back(c);
    }
    return name;
  }

  // Guards counts before allocating: each item takes at least `item_bytes`.
  uint64_t ReadCount(const char* what, uint64_t item_bytes) {
    const uint64_t count = Read<uint64_t>(what);
    const auto position = file_.tellg();
    file_.seekg(0, std::ios::end);
    const auto end = file_.tellg();
    file_.seekg(position);
    if (item_bytes > 0 && count > static_cast<uint64_t>(end - position) / item_bytes) {
      throw InputError(path_.string() + ": implausible " + what + " " + std::to_string(count) +
                       " (file too short)");
    }
    return count;
  }

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ifstream file_;
};

template <typename T>
void WriteLittleEndian(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace portcal
