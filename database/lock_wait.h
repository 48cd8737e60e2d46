// Waiting for another process's lock on a database, as COLMAP users run
// stages side by side from scripts and GUIs: SQLite's busy handler polls
// until the timeout (--Database.busy_timeout, process-wide) passes, and
// says on stderr every few seconds that it is waiting and for how long.
#pragma once

#include <chrono>
#include <string>

struct sqlite3;

namespace portcal {

// Seconds a statement waits for a lock before it fails (default 60).
// Throws OptionError for a negative or non-finite value.
void SetDatabaseBusyTimeout(double seconds);
double DatabaseBusyTimeout();

class LockWait {
 public:
  LockWait(std::string path, double timeout_s) : path_(std::move(path)), timeout_s_(timeout_s) {}
  // Installs this as `db`'s busy handler; it must outlive `db`.
  void Install(sqlite3* db);
  double timeout_s() const { return timeout_s_; }

 private:
  static int OnBusy(void* self, int attempt);

  std::string path_;
  double timeout_s_;
  std::chrono::steady_clock::time_point start_;
  double last_said_s_ = 0;
};

}  // namespace portcal
