#include "colmap_ext/util/new_paths.h"

namespace portcal {

NewPaths::NewPaths(const std::vector<std::filesystem::path>& paths) {
  for (const std::filesystem::path& path : paths) {
    if (!std::filesystem::exists(path)) created_.push_back(path);
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
