#include "database/lock_wait.h"

#include <sqlite3.h>

#include <cmath>
#include <thread>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

namespace {
double g_busy_timeout_s = 60;
}  // namespace

void SetDatabaseBusyTimeout(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) {
    throw OptionError("--Database.busy_timeout", seconds, "seconds >= 0");
  }
  g_busy_timeout_s = seconds;
}

double DatabaseBusyTimeout() { return g_busy_timeout_s; }

void LockWait::Install(sqlite3* db) { sqlite3_busy_handler(db, &LockWait::OnBusy, this); }

int LockWait::OnBusy(void* self, int attempt) {
  LockWait& wait = *static_cast<LockWait*>(self);
  const auto now = std::chrono::steady_clock::now();
  if (attempt == 0) {
    wait.start_ = now;
    wait.last_said_s_ = 0;
  }
  const double waited = std::chrono::duration<double>(now - wait.start_).count();
  if (waited >= wait.timeout_s_) return 0;  // SQLITE_BUSY to the statement
  // Said after 2 s, then every 5 s: a short wait is normal and silent.
  if (waited >= 2 && waited - wait.last_said_s_ >= (wait.last_said_s_ == 0 ? 2 : 5)) {
    LOG(WARNING) << wait.path_ << ": waiting for another process's lock on the database ("
                 << static_cast<int>(waited) << " s of " << wait.timeout_s_
                 << " s, --Database.busy_timeout)";
    wait.last_said_s_ = waited;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(attempt < 10 ? 2 : 20));
  return 1;
}

}  // namespace portcal
