// RAII wrappers around SQLite: a prepared statement that resets itself after
// each use, and a transaction that rolls back unless committed. This is the
// only place (with database.cc) that includes sqlite3.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace portcal {

class Statement {
 public:
  // Throws DatabaseError with the SQLite message, the database path and the
  // SQL on failure.
  Statement(sqlite3* db, const std::string& path, const std::string& sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // Parameters are 1-based. Bound buffers must outlive Step(): blobs are bound
  // without copying (SQLITE_STATIC).
  Statement& Bind(int index, int64_t value);
  Statement& Bind(int index, double value);  // NaN is stored as NULL
  Statement& Bind(int index, const std::string& value);
  Statement& BindBlob(int index, const void* data, size_t num_bytes);
  Statement& BindNull(int index);

  // True while a row is available; false when done. Throws on errors
  // (including "database is locked").
  bool Step();
  // Steps once and expects completion (INSERT/UPDATE/DELETE).
  void Execute();
  // Makes the statement reusable (clears bindings too).
  void Reset();

  int64_t ColumnInt64(int column) const;
  double ColumnDouble(int column) const;  // NULL, text, blob -> NaN
  bool ColumnIsNull(int column) const;
  std::string ColumnText(int column) const;
  std::vector<uint8_t> ColumnBlob(int column) const;

 private:
  [[noreturn]] void Fail(const std::string& what) const;

  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string path_;
  std::string sql_;
};

// BEGIN IMMEDIATE in the constructor (takes the write lock at once, so a
// concurrent writer fails fast instead of deadlocking), COMMIT only in
// Commit(), ROLLBACK in the destructor otherwise, including while unwinding.
class Transaction {
 public:
  Transaction(sqlite3* db, const std::string& path);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void Commit();

 private:
  sqlite3* db_;
  std::string path_;
  bool open_ = true;
};

// Runs SQL without results; throws DatabaseError naming path and SQL.
void ExecuteSql(sqlite3* db, const std::string& path, const std::string& sql);

}  // namespace portcal
