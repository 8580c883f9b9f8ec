#include "database/backend.hpp"

#include <sqlite3.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>
#include <utility>

namespace sailshape::detail {
namespace {

std::string describe(sqlite3* db, int rc) {
  std::string msg = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  return msg + " (" + sqlite3_errstr(rc) + ", code " + std::to_string(rc) + ")";
}

// True when this process cannot write the file or its folder, and no -wal with
// content lies beside it. SQLite would open such a WAL database read-only and
// leave read-only -wal and -shm files behind (or, in a read-only folder, fail
// to create them). A -wal with content holds commits the file lacks; reading
// the file as immutable would miss them.
bool unwritableWithoutPendingWal(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty() || path == ":memory:" || !fs::is_regular_file(path, ec)) return false;
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  const bool writable = ::access(path.c_str(), W_OK) == 0 && ::access(folder.c_str(), W_OK) == 0;
  if (writable) return false;
  const auto wal_size = fs::file_size(path + "-wal", ec);
  return ec || wal_size == 0;
}

// `path` as an SQLite URI ("file:...?immutable=1"): '%', '?' and '#' escaped.
std::string immutableUri(const std::string& path) {
  std::string uri = "file:";
  if (path.rfind("//", 0) == 0) uri += "//localhost";  // keep "//x" from reading as an authority
  for (char c : path) {
    if (c == '%') uri += "%25";
    else if (c == '?') uri += "%3f";
    else if (c == '#') uri += "%23";
    else uri += c;
  }
  return uri + "?immutable=1";
}


class SqliteConnection;

class SqliteStatement : public StatementBackend {
 public:
  SqliteStatement(SqliteConnection& db, const std::string& sql);
  ~SqliteStatement() override {
    if (stmt_) sqlite3_finalize(stmt_);
  }
  void bindInt(int index, int64_t value) override;
  void bindDouble(int index, double value) override;
  void bindText(int index, const std::string& value) override;
  void bindBlob(int index, const std::vector<uint8_t>& value) override;
  void bindNull(int index) override;
  bool step() override;
  void reset() override {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  int columnCount() const override { return sqlite3_column_count(stmt_); }
  std::string columnName(int c) const override { return sqlite3_column_name(stmt_, c); }
  bool isNull(int c) const override { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  bool isInteger(int c) const override { return sqlite3_column_type(stmt_, c) == SQLITE_INTEGER; }
  bool isFloat(int c) const override { return sqlite3_column_type(stmt_, c) == SQLITE_FLOAT; }
  bool isBlob(int c) const override { return sqlite3_column_type(stmt_, c) == SQLITE_BLOB; }
  int64_t columnInt(int c) const override { return sqlite3_column_int64(stmt_, c); }
  double columnDouble(int c) const override { return sqlite3_column_double(stmt_, c); }
  std::string columnText(int c) const override {
    const unsigned char* t = sqlite3_column_text(stmt_, c);
    return t ? std::string(reinterpret_cast<const char*>(t), sqlite3_column_bytes(stmt_, c)) : std::string();
  }
  std::vector<uint8_t> columnBlob(int c) const override {
    const auto* p = static_cast<const uint8_t*>(sqlite3_column_blob(stmt_, c));
    return p ? std::vector<uint8_t>(p, p + sqlite3_column_bytes(stmt_, c)) : std::vector<uint8_t>();
  }

 private:
  SqliteConnection* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

class SqliteConnection : public ConnectionBackend {
 public:
  SqliteConnection(const std::string& path, const OpenOptions& options);
  ~SqliteConnection() override {
    if (db_) sqlite3_close_v2(db_);
  }
  Backend kind() const override { return Backend::SQLite; }
  void exec(const std::string& sql) override {
    char* err = nullptr;
    const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err);
    sqlite3_free(err);
    check(rc, "Database::exec");
  }
  std::unique_ptr<StatementBackend> prepare(const std::string& sql) override {
    return std::make_unique<SqliteStatement>(*this, sql);
  }
  int64_t lastInsertId() override { return sqlite3_last_insert_rowid(db_); }
  bool readOnly() const override { return sqlite3_db_readonly(db_, "main") == 1; }
  int userVersion() override {
    SqliteStatement s(*this, "PRAGMA user_version");
    s.step();
    return static_cast<int>(s.columnInt(0));
  }
  void setUserVersion(int version) override { exec("PRAGMA user_version=" + std::to_string(version)); }
  int64_t tableCount() override {
    SqliteStatement s(*this, "SELECT count(*) FROM sqlite_schema WHERE type = 'table'");
    s.step();
    return s.columnInt(0);
  }
  std::vector<std::string> integrityCheck() override;
  void backupTo(const std::string& dest_path) override;
  void begin() override { exec("BEGIN IMMEDIATE"); }
  void commit() override { exec("COMMIT"); }
  void rollback() noexcept override { sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr); }
  void beginSnapshot() override { exec("BEGIN"); }
  void lockSchema(bool) override {}
  void enableConcurrentReaders() override;

  sqlite3* handle() const { return db_; }
  // Throws DatabaseError (DatabaseBusy for SQLITE_BUSY/LOCKED) when `rc` is an error.
  void check(int rc, const char* what) const;

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
  int busy_timeout_ms_ = 0;
};

void SqliteConnection::check(int rc, const char* what) const {
  if (rc == SQLITE_OK || rc == SQLITE_ROW || rc == SQLITE_DONE) return;
  const int primary = rc & 0xff;
  if (primary == SQLITE_BUSY || primary == SQLITE_LOCKED)
    throw DatabaseBusy(std::string("[") + what + "] " + path_ + ": database is locked by another connection (waited " +
                       std::to_string(busy_timeout_ms_) + " ms): " + describe(db_, rc));
  if (primary == SQLITE_NOTADB)
    throw DatabaseError(std::string("[") + what + "] " + path_ + ": not an SQLite database (or encrypted); left untouched");
  if (primary == SQLITE_CORRUPT)
    throw DatabaseError(std::string("[") + what + "] " + path_ + ": database file is damaged: " + describe(db_, rc));
  throw DatabaseError(std::string("[") + what + "] " + path_ + ": " + describe(db_, rc));
}

SqliteConnection::SqliteConnection(const std::string& path, const OpenOptions& options)
    : path_(path), busy_timeout_ms_(options.busy_timeout_ms) {
  if (options.busy_timeout_ms < 0)
    throw DatabaseError("[Database] busy_timeout_ms must be >= 0 (got " + std::to_string(options.busy_timeout_ms) + ")");
  int flags = options.read_only ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE;
  if (options.create && !options.read_only) flags |= SQLITE_OPEN_CREATE;
  flags |= SQLITE_OPEN_NOMUTEX;
  // A file this process may not change is read as immutable: no locks and no -wal or
  // -shm beside it; writes then fail as "attempt to write a readonly database".
  std::string name = path;
  if (unwritableWithoutPendingWal(path)) {
    name = immutableUri(path);
    flags = SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX;
  }
  const int rc = sqlite3_open_v2(name.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string msg = describe(db_, rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw DatabaseError("[Database] " + path + ": cannot open: " + msg);
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    check(sqlite3_busy_timeout(db_, options.busy_timeout_ms), "Database");
    // A read first: SQLite opens files lazily, and a foreign file must be
    // refused before any pragma could write to it.
    exec("SELECT count(*) FROM sqlite_schema");
    exec("PRAGMA foreign_keys=ON");
    exec("PRAGMA synchronous=NORMAL");  // durable with WAL up to the last checkpointed commit; never corrupt
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

// SQLite answers SQLITE_BUSY at once, without its busy handler, when another
// connection holds a lock during the switch from a rollback journal to WAL (the
// switch needs the file alone). Waiting here as the busy handler would keeps the
// open's promise: locked only after busy_timeout_ms.
void SqliteConnection::enableConcurrentReaders() {
  if (readOnly()) return;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(busy_timeout_ms_);
  for (auto pause = std::chrono::milliseconds(1);; pause = std::min(pause * 2, std::chrono::milliseconds(50))) {
    try {
      exec("PRAGMA journal_mode=WAL");
      return;
    } catch (const DatabaseBusy&) {
      if (std::chrono::steady_clock::now() + pause > deadline) throw;
    }
    std::this_thread::sleep_for(pause);
  }
}

std::vector<std::string> SqliteConnection::integrityCheck() {
  std::vector<std::string> problems;
  SqliteStatement s(*this, "PRAGMA integrity_check");
  while (s.step()) {
    std::string line = s.columnText(0);
    if (line != "ok") problems.push_back(line);
  }
  SqliteStatement fk(*this, "PRAGMA foreign_key_check");
  while (fk.step())
    problems.push_back("foreign key: row " + fk.columnText(1) + " of " + fk.columnText(0) + " refers to a missing row of " +
                       fk.columnText(2));
  return problems;
}

void SqliteConnection::backupTo(const std::string& dest_path) {
  sqlite3* dest = nullptr;
  int rc = sqlite3_open_v2(dest_path.c_str(), &dest, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  if (rc != SQLITE_OK) {
    const std::string msg = describe(dest, rc);
    sqlite3_close(dest);
    throw DatabaseError("[Database::backupTo] " + dest_path + ": cannot open: " + msg);
  }
  sqlite3_busy_timeout(dest, busy_timeout_ms_);
  sqlite3_backup* b = sqlite3_backup_init(dest, "main", db_, "main");
  if (!b) {
    const std::string msg = sqlite3_errmsg(dest);
    sqlite3_close(dest);
    throw DatabaseError("[Database::backupTo] " + dest_path + ": " + msg);
  }
  // Pages in steps so writers on the source are not held up for the whole copy.
  do {
    rc = sqlite3_backup_step(b, 256);
    if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) sqlite3_sleep(10);
  } while (rc == SQLITE_OK || rc == SQLITE_BUSY || rc == SQLITE_LOCKED);
  sqlite3_backup_finish(b);
  const int final_rc = sqlite3_errcode(dest);
  const std::string msg = describe(dest, rc);
  sqlite3_close(dest);
  if (rc != SQLITE_DONE || (final_rc != SQLITE_OK && final_rc != SQLITE_DONE))
    throw DatabaseError("[Database::backupTo] " + path_ + " -> " + dest_path + ": " + msg);
}

SqliteStatement::SqliteStatement(SqliteConnection& db, const std::string& sql) : db_(&db) {
  db_->check(sqlite3_prepare_v2(db.handle(), sql.c_str(), static_cast<int>(sql.size()), &stmt_, nullptr),
             "Statement::prepare");
}

void SqliteStatement::bindInt(int index, int64_t value) {
  db_->check(sqlite3_bind_int64(stmt_, index, value), "Statement::bind");
}
void SqliteStatement::bindDouble(int index, double value) {
  db_->check(sqlite3_bind_double(stmt_, index, value), "Statement::bind");
}
void SqliteStatement::bindText(int index, const std::string& value) {
  db_->check(sqlite3_bind_text(stmt_, index, value.data(), static_cast<int>(value.size()), SQLITE_TRANSIENT),
             "Statement::bind");
}
void SqliteStatement::bindBlob(int index, const std::vector<uint8_t>& value) {
  db_->check(sqlite3_bind_blob64(stmt_, index, value.data(), value.size(), SQLITE_TRANSIENT), "Statement::bind");
}
void SqliteStatement::bindNull(int index) { db_->check(sqlite3_bind_null(stmt_, index), "Statement::bind"); }

bool SqliteStatement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  sqlite3_reset(stmt_);
  db_->check(rc, "Statement::step");
  return false;
}

}  // namespace

std::unique_ptr<ConnectionBackend> openSqlite(const std::string& path, const OpenOptions& options) {
  return std::make_unique<SqliteConnection>(path, options);
}

}  // namespace sailshape::detail
