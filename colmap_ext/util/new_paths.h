// Files and folders a run creates, removed again unless the run succeeds:
// a failed stage leaves its output folder as it was (no half-made database,
// no staging folder, no folder that was not there).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace portcal {

class NewPaths {
 public:
  // Notes which of `paths` exist now; those that do not are the run's.
  explicit NewPaths(const std::vector<std::filesystem::path>& paths);
  // Removes the run's paths (recursively) unless Keep() was called.
  ~NewPaths();
  NewPaths(const NewPaths&) = delete;
  NewPaths& operator=(const NewPaths&) = delete;

  void Keep() { keep_ = true; }

 private:
  std::vector<std::filesystem::path> created_;
  bool keep_ = false;
};

// For Options::Check(): an output folder that is a file is an OptionError
// naming `option`, before any work.
void CheckOutputFolder(const std::string& option, const std::string& path);

}  // namespace portcal
