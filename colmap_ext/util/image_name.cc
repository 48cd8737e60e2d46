#include "colmap_ext/util/image_name.h"

#include <cstdio>

#include "colmap_ext/util/error.h"

namespace portcal {

namespace {

bool IsControl(unsigned char c) { return c < 0x20 || c == 0x7f; }

std::string Hex(unsigned char c) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%02x", c);
  return text;
}

}  // namespace

std::string ImageNameProblem(const std::string& name) {
  if (name.empty()) return "is empty";
  for (const char c : name) {
    if (IsControl(static_cast<unsigned char>(c))) {
      return "holds a control character (byte " + Hex(static_cast<unsigned char>(c)) +
             "; rename the file: image names may hold any character but control characters)";
    }
  }
  return "";
}

std::string ShownImageName(const std::string& name) {
  std::string shown;
  for (const char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    shown += IsControl(u) ? "\\x" + Hex(u).substr(2) : std::string(1, c);
  }
  return shown;
}

void CheckImageName(const std::string& name, const std::string& where) {
  const std::string problem = ImageNameProblem(name);
  if (!problem.empty())
    throw InputError(where + ": image name '" + ShownImageName(name) + "' " + problem);
}

}  // namespace portcal
