#include "database/session_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "colmap_ext/util/error.h"

namespace portcal {

SessionLock::SessionLock(const std::filesystem::path& database, const std::string& what) {
  fd_ = open(database.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0)
    throw DatabaseError(database.string() + ": cannot open it to hold it (" + std::strerror(errno) +
                        ")");
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK) {
      throw DatabaseError(
          database.string() + ": another " + what +
          " is using this database (one at a time: finish it first, or give another "
          "--database_path)");
    }
    throw DatabaseError(database.string() + ": cannot hold it (" + std::strerror(error) + ")");
  }
}

SessionLock::~SessionLock() {
  if (fd_ >= 0) close(fd_);  // releases the lock
}

}  // namespace portcal
