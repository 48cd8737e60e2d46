// A database file that a stage creates is removed again when the stage
// fails: a failed run leaves no schema-only database behind. Declare it
// before the Database that opens the file (it is then destroyed after the
// connection is closed).
#pragma once

#include <filesystem>

namespace portcal {

class NewDatabaseFile {
 public:
  // Notes whether `path` exists now.
  explicit NewDatabaseFile(const std::filesystem::path& path);
  // Removes the file (and its journal) if it did not exist and Keep() was
  // not called.
  ~NewDatabaseFile();
  NewDatabaseFile(const NewDatabaseFile&) = delete;
  NewDatabaseFile& operator=(const NewDatabaseFile&) = delete;

  void Keep() { keep_ = true; }

 private:
  std::filesystem::path path_;
  bool keep_;
};

}  // namespace portcal
