#pragma once
// RAII wrappers over SQLite: a connection, a prepared statement and a
// transaction that rolls back unless committed. sqlite3.h stays in the .cpp;
// every SQLite error code becomes a DatabaseError naming the call and the file.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace sailshape {

// SQLite refused an operation (bad SQL, constraint, I/O, not a database, ...).
struct DatabaseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The database stayed locked by another connection for the whole busy timeout.
struct DatabaseBusy : DatabaseError {
  using DatabaseError::DatabaseError;
};

struct OpenOptions {
  bool create = true;           // false: a missing file is an error instead of a new database
  bool read_only = false;
  int busy_timeout_ms = 5000;   // how long a write waits for another connection's lock
};

class Statement;

class Database {
 public:
  // Opens (or creates) `path`, checks that it is an SQLite database before
  // anything is written, then sets foreign_keys=ON and the busy timeout.
  // Writes nothing: WAL mode and the schema are openSailDatabase()'s
  // (database/schema.hpp), once the file is known to be ours. A file this
  // process may not write (mode 0444, or in a read-only folder) is opened
  // read-only and immutable, so reading it leaves no -wal or -shm behind.
  explicit Database(const std::string& path, const OpenOptions& options = {});
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(const std::string& sql);
  Statement prepare(const std::string& sql);
  int64_t lastInsertId() const;
  // True when SQLite opened the file read-only (asked for, or not writable here).
  bool readOnly() const;
  int userVersion();
  void setUserVersion(int version);
  int busyTimeoutMs() const { return busy_timeout_ms_; }

  // PRAGMA integrity_check and foreign_key_check; empty when the file is consistent.
  std::vector<std::string> integrityCheck();
  // Online copy of the whole database to `dest_path` (SQLite backup API);
  // readers and writers on this connection may continue meanwhile.
  void backupTo(const std::string& dest_path);

  const std::string& path() const { return path_; }
  sqlite3* handle() const { return db_; }
  // Throws DatabaseError (DatabaseBusy for SQLITE_BUSY/LOCKED) when `rc` is an error.
  void check(int rc, const char* what) const;

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
  int busy_timeout_ms_ = 0;
};

class Statement {
 public:
  Statement(Database& db, const std::string& sql);
  ~Statement();
  Statement(Statement&& other) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& operator=(Statement&&) = delete;

  // Parameters are 1-based, as in SQLite.
  Statement& bind(int index, int64_t value);
  Statement& bind(int index, int value) { return bind(index, static_cast<int64_t>(value)); }
  Statement& bind(int index, double value);
  Statement& bind(int index, const std::string& value);
  Statement& bind(int index, const char* value) { return bind(index, std::string(value)); }
  Statement& bind(int index, const std::optional<double>& value);
  Statement& bindBlob(int index, const std::vector<uint8_t>& value);
  Statement& bindNull(int index);

  // True while a row is available; false when done.
  bool step();
  // Steps a statement that returns no rows.
  void run();
  void reset();

  int columnCount() const;
  std::string columnName(int column) const;
  bool isNull(int column) const;
  bool isInteger(int column) const;
  bool isFloat(int column) const;
  int64_t columnInt(int column) const;
  double columnDouble(int column) const;
  std::string columnText(int column) const;
  std::vector<uint8_t> columnBlob(int column) const;

 private:
  Database* db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
};

// BEGIN IMMEDIATE (takes the write lock up front, waiting the busy timeout);
// rolls back in the destructor unless commit() was called.
class Transaction {
 public:
  explicit Transaction(Database& db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& db_;
  bool done_ = false;
};

}  // namespace sailshape
