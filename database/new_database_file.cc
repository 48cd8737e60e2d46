#include "database/new_database_file.h"

#include <system_error>

namespace portcal {

NewDatabaseFile::NewDatabaseFile(const std::filesystem::path& path)
    : path_(path), keep_(std::filesystem::exists(path)) {}

NewDatabaseFile::~NewDatabaseFile() {
  if (keep_) return;
  std::error_code ignored;  // nothing to do about a file that cannot go
  std::filesystem::remove(path_, ignored);
  std::filesystem::remove(path_.string() + "-journal", ignored);
}

}  // namespace portcal
