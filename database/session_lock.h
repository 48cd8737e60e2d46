// One long session per database: a live calibration holds its database for
// minutes while idle between keeps, so SQLite's own locks (taken per
// transaction) let a second session start on the same file and both then
// write images of the same names and stall on each other's transactions.
// An advisory flock(2) on the database file, held for the session, refuses
// the second one at start. flock, not fcntl: SQLite's locks are fcntl's,
// which closing any other descriptor of the file would drop; flock's are
// the descriptor's own. The lock is released by the kernel if the process
// dies. Declare it after the Database (it is then closed after it).
#pragma once

#include <filesystem>
#include <string>

namespace portcal {

class SessionLock {
 public:
  // Throws DatabaseError naming the file and `what` holds it when another
  // process (or another SessionLock) holds it.
  SessionLock(const std::filesystem::path& database, const std::string& what);
  ~SessionLock();
  SessionLock(const SessionLock&) = delete;
  SessionLock& operator=(const SessionLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace portcal
