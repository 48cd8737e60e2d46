#include "database/integrity_check.h"

#include <sqlite3.h>

#include <string>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/string_utils.h"
#include "database/lock_wait.h"
#include "database/statement.h"

namespace portcal {

namespace {

// At most this many of SQLite's problem lines go into the message.
constexpr int kMaxProblems = 3;

class ReadOnlyConnection {
 public:
  explicit ReadOnlyConnection(const std::string& path) : lock_wait_(path, DatabaseBusyTimeout()) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
      throw DatabaseError(path + ": no such database file");
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw DatabaseError(path + ": cannot open database: " + message);
    }
    lock_wait_.Install(db_);  // a writer elsewhere: wait as every stage does
  }
  ~ReadOnlyConnection() { sqlite3_close(db_); }
  ReadOnlyConnection(const ReadOnlyConnection&) = delete;
  ReadOnlyConnection& operator=(const ReadOnlyConnection&) = delete;
  sqlite3* get() const { return db_; }

 private:
  LockWait lock_wait_;  // outlives db_
  sqlite3* db_ = nullptr;
};

std::string DamagedAdvice() {
  return "; the file was not changed: restore it from a copy, or re-run the stages that made it";
}

void CheckPages(sqlite3* db, const std::string& path) {
  std::string problems;
  int num_problems = 0;
  try {
    Statement check(db, path, "PRAGMA quick_check(" + std::to_string(kMaxProblems) + ");");
    while (check.Step()) {
      const std::string text = check.ColumnText(0);
      if (text == "ok") return;
      // A row may hold several lines, headed by "*** in database main ***".
      for (const std::string& line : SplitTokens(text, "\n")) {
        if (line.rfind("***", 0) == 0) continue;
        problems += (num_problems++ ? "; " : "") + line;
      }
    }
  } catch (const DatabaseError& e) {
    // A schema too damaged to parse fails the pragma itself (its message
    // says the file is damaged).
    throw InputError(e.what());
  }
  throw InputError(path + ": the database file is damaged (PRAGMA quick_check: " + problems + ")" +
                   DamagedAdvice());
}

// foreign_key_check's rows: table, rowid, referred table, constraint index.
void CheckReferences(sqlite3* db, const std::string& path) {
  Statement check(db, path, "PRAGMA foreign_key_check;");
  std::string problems;
  int num_problems = 0;
  while (check.Step()) {
    if (num_problems < kMaxProblems) {
      problems += std::string(num_problems ? "; " : "") + "a row of " + check.ColumnText(0) +
                  " (rowid " + std::to_string(check.ColumnInt64(1)) +
                  ") refers to a missing row of " + check.ColumnText(2);
    }
    ++num_problems;
  }
  if (num_problems == 0) return;
  throw InputError(path + ": the database is inconsistent: " + std::to_string(num_problems) +
                   " rows refer to rows it does not hold (" + problems +
                   (num_problems > kMaxProblems ? "; ..." : "") + ")" + DamagedAdvice());
}

}  // namespace

void CheckDatabaseIntegrity(const std::filesystem::path& path) {
  const ReadOnlyConnection connection(path.string());
  CheckPages(connection.get(), path.string());
  CheckReferences(connection.get(), path.string());
}

}  // namespace portcal
