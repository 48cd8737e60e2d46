#include "colmap_ext/util/confined_path.h"

#include "colmap_ext/util/error.h"

namespace portcal {
namespace fs = std::filesystem;

namespace {

// `path` with its existing part's links resolved; what does not exist yet
// is appended as it is (lexically normalised).
fs::path Resolved(const fs::path& path) {
  std::error_code error;
  const fs::path resolved = fs::weakly_canonical(path, error);
  return error ? fs::absolute(path).lexically_normal() : resolved;
}

bool Inside(const fs::path& child, const fs::path& parent) {
  const fs::path relative = child.lexically_relative(parent);
  return !relative.empty() && *relative.begin() != "..";
}

}  // namespace

fs::path ConfinedPath(const fs::path& folder, const std::string& name, const std::string& what) {
  const auto refuse = [&](const std::string& why) {
    std::string shown;
    for (const char c : name) shown += static_cast<unsigned char>(c) < 0x20 ? '?' : c;
    throw InputError(what + " '" + shown + "' " + why + "; names must stay inside " +
                     folder.string());
  };
  if (name.empty()) refuse("is empty");
  for (const char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) refuse("holds a control character");
  }
  const fs::path relative(name);
  if (relative.is_absolute() || relative.has_root_name() || relative.has_root_directory())
    refuse("is absolute");
  for (const fs::path& part : relative) {
    if (part == "..") refuse("climbs out with '..'");
  }
  const fs::path joined = folder / relative;
  if (!Inside(Resolved(joined), Resolved(folder)))
    refuse("leaves the folder through a symbolic link");
  std::error_code error;
  const fs::file_status status = fs::symlink_status(joined, error);
  if (fs::exists(status) && !fs::is_regular_file(fs::status(joined, error)))
    refuse("names something not a regular file");
  return joined;
}

void CheckOutputFile(const std::string& option, const std::string& output,
                     const std::vector<std::string>& inputs) {
  std::error_code error;
  for (const std::string& input : inputs) {
    if (!input.empty() && fs::exists(input, error) && fs::exists(output, error) &&
        fs::equivalent(input, output, error)) {
      throw OptionError(option, output, "a new file, not the input " + input);
    }
  }
  const fs::file_status status = fs::status(output, error);
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw OptionError(option, output, "a regular file (it names a folder, a device or a fifo)");
  }
}

}  // namespace portcal
