#pragma once
// The store's connection, statement and transaction, one interface over two
// backends: an SQLite file (embedded, the default) and a PostgreSQL server
// (`postgresql://user@host:port/dbname`, the loft's shared store). Every query
// of database/ is written once, in SQLite's spelling with `?` placeholders;
// database/dialect.hpp turns it into PostgreSQL's. sqlite3.h and libpqxx stay
// in the backends' .cpp files; every error of either becomes a DatabaseError
// naming the call and the store.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace sailshape {

// The store refused an operation (bad SQL, constraint, I/O, not a database, ...).
struct DatabaseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The database stayed locked by another connection for the whole busy timeout.
struct DatabaseBusy : DatabaseError {
  using DatabaseError::DatabaseError;
};

// PostgreSQL aborted the transaction because it conflicted with a concurrent
// one (serialization failure or deadlock); running it again may succeed.
// runTransaction() does that.
struct SerializationFailure : DatabaseError {
  using DatabaseError::DatabaseError;
};

// The connection to the PostgreSQL server was lost; the open transaction was
// not committed (the server rolls it back).
struct ConnectionLost : DatabaseError {
  using DatabaseError::DatabaseError;
};

enum class Backend { SQLite, PostgreSQL };

// True for a `postgresql://` or `postgres://` connection URL; anything else is an SQLite file path.
bool isPostgresUrl(const std::string& location);

struct OpenOptions {
  bool create = true;           // false: a missing SQLite file is an error instead of a new database
  bool read_only = false;
  int busy_timeout_ms = 5000;   // how long a write waits for another connection's lock
};

namespace detail {
class ConnectionBackend;
class StatementBackend;
}  // namespace detail

class Statement;

class Database {
 public:
  // `location` is an SQLite file path or a PostgreSQL URL.
  // SQLite: opens (or creates) the file, checks that it is an SQLite database
  // before anything is written, then sets foreign_keys=ON and the busy timeout.
  // Writes nothing: WAL mode and the schema are openSailDatabase()'s
  // (database/schema.hpp), once the file is known to be ours. A file this
  // process may not write (mode 0444, or in a read-only folder) is opened
  // read-only and immutable, so reading it leaves no -wal or -shm behind.
  // PostgreSQL: connects (password from ~/.pgpass or PGPASSWORD, sslmode as
  // libpq reads it); the database must exist on the server.
  explicit Database(const std::string& location, const OpenOptions& options = {});
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  Backend backend() const;
  void exec(const std::string& sql);
  Statement prepare(const std::string& sql);
  // The id the last INSERT on this connection gave its row.
  int64_t lastInsertId() const;
  // True when the store was opened read-only (asked for, or an SQLite file not writable here).
  bool readOnly() const;
  // The schema version (SQLite: PRAGMA user_version; PostgreSQL: table sailshape_schema).
  int userVersion();
  void setUserVersion(int version);
  int busyTimeoutMs() const { return busy_timeout_ms_; }
  // Tables in the store (of any application), sailshape's version table excepted.
  int64_t tableCount();

  // Consistency problems, empty when there are none. SQLite: PRAGMA
  // integrity_check and foreign_key_check. PostgreSQL (whose pages the server
  // checks itself): every foreign key's rows checked for a missing referent.
  std::vector<std::string> integrityCheck();
  // Online copy of the whole SQLite database to `dest_path` (SQLite backup API);
  // readers and writers on this connection may continue meanwhile. A
  // PostgreSQL store throws (`sailshape db copy` copies it).
  void backupTo(const std::string& dest_path);

  // Starts a write transaction: SQLite BEGIN IMMEDIATE (the write lock up front,
  // waiting the busy timeout); PostgreSQL BEGIN ISOLATION LEVEL SERIALIZABLE.
  // Transaction and runTransaction() call these.
  void begin();
  void commit();
  void rollback() noexcept;
  // Starts a read-only transaction that sees one snapshot of the store until
  // rollback() (SQLite: BEGIN; PostgreSQL: REPEATABLE READ, READ ONLY).
  void beginSnapshot();
  // Serialises schema migrations between processes (PostgreSQL: a session
  // advisory lock; SQLite: nothing, its write lock does it).
  void lockSchema(bool lock);
  // Lets readers read while a writer writes (SQLite: WAL; PostgreSQL: always so).
  void enableConcurrentReaders();

  // The file path, or the URL without its password.
  const std::string& path() const { return path_; }
  detail::ConnectionBackend& connection() const { return *impl_; }

 private:
  std::unique_ptr<detail::ConnectionBackend> impl_;
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
  // Ready to run again; the bindings are cleared.
  void reset();

  int columnCount() const;
  std::string columnName(int column) const;
  bool isNull(int column) const;
  bool isInteger(int column) const;
  bool isFloat(int column) const;
  bool isBlob(int column) const;
  int64_t columnInt(int column) const;
  double columnDouble(int column) const;
  std::string columnText(int column) const;
  std::vector<uint8_t> columnBlob(int column) const;

 private:
  std::unique_ptr<detail::StatementBackend> impl_;
};

// A write transaction (Database::begin); rolls back in the destructor unless
// commit() was called.
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

// Runs `body` inside a write transaction and commits. When PostgreSQL aborts
// it for a conflict with a concurrent writer (SerializationFailure), rolls
// back, waits a random while that grows with each attempt and runs `body`
// again, up to `max_attempts` times; then throws the last failure. Returns the
// number of attempts it took. `body` must do nothing outside the store that
// it could not repeat.
int runTransaction(Database& db, const std::function<void()>& body, int max_attempts = 40);

}  // namespace sailshape
