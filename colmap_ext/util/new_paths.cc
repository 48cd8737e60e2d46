#include "colmap_ext/util/new_paths.h"

#include "colmap_ext/util/error.h"

namespace portcal {

NewPaths::NewPaths(const std::vector<std::filesystem::path>& paths) {
  for (const std::filesystem::path& path : paths) {
    if (std::filesystem::exists(path)) continue;
    // The outermost missing folder: create_directories makes the parents too.
    std::filesystem::path outermost = std::filesystem::absolute(path);
    while (outermost.has_parent_path() && outermost.parent_path() != outermost &&
           !std::filesystem::exists(outermost.parent_path())) {
      outermost = outermost.parent_path();
    }
    created_.push_back(outermost);
  }
}

void CheckOutputFolder(const std::string& option, const std::string& path) {
  if (std::filesystem::exists(path) && !std::filesystem::is_directory(path)) {
    throw OptionError(option, path, "a folder (it is a file)");
  }
}

NewPaths::~NewPaths() {
  if (keep_) return;
  // Innermost first does not matter: remove_all of a parent takes the rest.
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) {
    std::error_code ignored;
    std::filesystem::remove_all(*it, ignored);
  }
}

}  // namespace portcal
