#include "database/statement.h"

#include <sqlite3.h>

#include <cmath>
#include <cstring>

#include "colmap_ext/util/error.h"
#include "colmap_ext/util/logging.h"

namespace portcal {

namespace {

// SQLite's message with what it means for the user where SQLite's own words
// do not say it (a damaged file, a full disk, a dangling reference).
std::string Describe(sqlite3* db, int code) {
  std::string message = sqlite3_errmsg(db);
  const int extended = sqlite3_extended_errcode(db);
  switch (code & 0xFF) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return message +
             " (another process held the database past --Database.busy_timeout; wait for it to "
             "finish, "
             "or give a longer timeout)";
    case SQLITE_CORRUPT:
      return "the database file is damaged (SQLite: " + message +
             "); restore it from a copy, or re-run the stages that made it";
    case SQLITE_NOTADB:
      return "not an SQLite database (SQLite: " + message + ")";
    case SQLITE_FULL:
      return "the disk is full (SQLite: " + message + "); free some space and run again";
    case SQLITE_READONLY:
      return "the file (or its folder, for the journal) cannot be written (SQLite: " + message +
             ")";
    case SQLITE_IOERR:
      return "the file could not be read or written (SQLite: " + message +
             "; a full disk or a file over its size "
             "limit, a failing disk, a removed drive or a network folder that went away)";
    case SQLITE_CONSTRAINT:
      if (extended == SQLITE_CONSTRAINT_FOREIGNKEY) {
        return "a row would refer to a camera or image the database does not hold (SQLite: " +
               message + "); the database is inconsistent";
      }
      return message;
    default:
      return message;
  }
}

}  // namespace

Statement::Statement(sqlite3* db, const std::string& path, const std::string& sql)
    : db_(db), path_(path), sql_(sql) {
  const int code = sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt_, nullptr);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

// The statement goes to the debug log, not the message: it helps a
// developer, and a user reads what failed and why.
void Statement::Fail(const std::string& what) const {
  VLOG(1) << path_ << ": failed SQL: " << sql_;
  throw DatabaseError(path_ + ": " + what);
}

Statement& Statement::Bind(int index, int64_t value) {
  const int code = sqlite3_bind_int64(stmt_, index, value);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
  return *this;
}

Statement& Statement::Bind(int index, double value) {
  if (std::isnan(value)) return BindNull(index);
  const int code = sqlite3_bind_double(stmt_, index, value);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
  return *this;
}

Statement& Statement::Bind(int index, const std::string& value) {
  const int code = sqlite3_bind_text(stmt_, index, value.c_str(), static_cast<int>(value.size()),
                                     SQLITE_TRANSIENT);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
  return *this;
}

Statement& Statement::BindBlob(int index, const void* data, size_t num_bytes) {
  const int code =
      sqlite3_bind_blob64(stmt_, index, num_bytes ? data : "", num_bytes, SQLITE_STATIC);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
  return *this;
}

Statement& Statement::BindNull(int index) {
  const int code = sqlite3_bind_null(stmt_, index);
  if (code != SQLITE_OK) Fail(Describe(db_, code));
  return *this;
}

bool Statement::Step() {
  const int code = sqlite3_step(stmt_);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  const std::string message = Describe(db_, code);
  sqlite3_reset(stmt_);
  Fail(message);
}

void Statement::Execute() {
  if (Step()) Fail("statement returned rows where none were expected");
  Reset();
}

void Statement::Reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

int64_t Statement::ColumnInt64(int column) const { return sqlite3_column_int64(stmt_, column); }

double Statement::ColumnDouble(int column) const {
  // Text or a blob in a REAL column (an edited row) is no number: NaN, which
  // the readers refuse, rather than SQLite's 0.0.
  const int type = sqlite3_column_type(stmt_, column);
  if (type == SQLITE_NULL || type == SQLITE_TEXT || type == SQLITE_BLOB) return std::nan("");
  return sqlite3_column_double(stmt_, column);
}

bool Statement::ColumnIsNull(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

std::string Statement::ColumnText(int column) const {
  const unsigned char* text = sqlite3_column_text(stmt_, column);
  if (text == nullptr) return "";
  return std::string(reinterpret_cast<const char*>(text), sqlite3_column_bytes(stmt_, column));
}

std::vector<uint8_t> Statement::ColumnBlob(int column) const {
  const void* data = sqlite3_column_blob(stmt_, column);
  const int num_bytes = sqlite3_column_bytes(stmt_, column);
  std::vector<uint8_t> blob(num_bytes);
  if (num_bytes > 0) std::memcpy(blob.data(), data, num_bytes);
  return blob;
}

void ExecuteSql(sqlite3* db, const std::string& path, const std::string& sql) {
  char* error = nullptr;
  const int code = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  if (code != SQLITE_OK) {
    // sqlite3_exec's own text is the more precise for plain failures (the
    // statement's error); Describe's where it adds what the code means.
    std::string message = error ? error : Describe(db, code);
    if ((code & 0xFF) != SQLITE_ERROR) message = Describe(db, code);
    sqlite3_free(error);
    VLOG(1) << path << ": failed SQL: " << sql;
    throw DatabaseError(path + ": " + message);
  }
}

Transaction::Transaction(sqlite3* db, const std::string& path) : db_(db), path_(path) {
  ExecuteSql(db_, path_, "BEGIN IMMEDIATE TRANSACTION;");
}

Transaction::~Transaction() {
  if (open_) sqlite3_exec(db_, "ROLLBACK;", nullptr, nullptr, nullptr);
}

void Transaction::Commit() {
  PORTCAL_CHECK(open_);
  ExecuteSql(db_, path_, "COMMIT;");
  open_ = false;
}

}  // namespace portcal
