// The PostgreSQL backend of the store, through libpqxx. Statements run with
// the extended protocol (text parameters, BYTEA as hex text), one round trip
// each; a write transaction is SERIALIZABLE, so concurrent imports behave as
// if one ran after the other or one is aborted with SQLSTATE 40001 and retried
// (runTransaction).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <pqxx/pqxx>

#include "database/backend.hpp"
#include "database/dialect.hpp"

namespace sailshape::detail {
namespace {

// pg_advisory_lock key of schema migrations: "sail" in ASCII.
constexpr int64_t kSchemaLockKey = 0x7361696c;

// Object ids of the built-in types a result column may have (pg_type.h).
constexpr pqxx::oid kBool = 16, kBytea = 17, kInt8 = 20, kInt2 = 21, kInt4 = 23, kFloat4 = 700, kFloat8 = 701,
                    kNumeric = 1700;

std::string oneLine(std::string s) {
  for (const char* prefix : {"ERROR:  ", "FATAL:  "})
    if (s.rfind(prefix, 0) == 0) s.erase(0, std::char_traits<char>::length(prefix));
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}

bool connectionClass(const std::string& sqlstate) {
  // 08: connection exception; 57P01-57P03: the server shut the session down.
  return sqlstate.rfind("08", 0) == 0 || sqlstate == "57P01" || sqlstate == "57P02" || sqlstate == "57P03";
}

// Rethrows the pqxx exception being handled as the store's own.
[[noreturn]] void rethrow(const char* what, const std::string& name) {
  const std::string where = std::string("[") + what + "] " + name + ": ";
  const std::string lost = "lost the connection to the PostgreSQL server; nothing of the open transaction was stored (";
  try {
    throw;
  } catch (const pqxx::in_doubt_error& e) {
    throw ConnectionLost(where + "lost the connection to the PostgreSQL server during COMMIT; whether it was stored is unknown (" +
                         oneLine(e.what()) + ")");
  } catch (const pqxx::broken_connection& e) {
    throw ConnectionLost(where + lost + oneLine(e.what()) + ")");
  } catch (const pqxx::statement_completion_unknown& e) {
    throw DatabaseError(where + oneLine(e.what()) + " (SQLSTATE 40003)");
  } catch (const pqxx::transaction_rollback& e) {
    // libpqxx 6 gives 40001 (serialization failure) and 40P01 (deadlock) these
    // classes, outside sql_error.
    throw SerializationFailure(where + "transaction aborted by a concurrent writer (" + oneLine(e.what()) + ")");
  } catch (const pqxx::sql_error& e) {
    const std::string state = e.sqlstate();
    const std::string msg = oneLine(e.what());
    if (state == "40001" || state == "40P01")
      throw SerializationFailure(where + "transaction aborted by a concurrent writer (" + msg + ", SQLSTATE " + state + ")");
    if (state == "55P03")
      throw DatabaseBusy(where + "database is locked by another connection: " + msg);
    if (connectionClass(state)) throw ConnectionLost(where + lost + msg + ")");
    throw DatabaseError(where + msg + (state.empty() ? "" : " (SQLSTATE " + state + ")"));
  } catch (const pqxx::failure& e) {
    throw DatabaseError(where + oneLine(e.what()));
  }
}

std::string hexBytea(const std::vector<uint8_t>& bytes) {
  static const char digits[] = "0123456789abcdef";
  std::string out = "\\x";
  out.resize(2 + 2 * bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) {
    out[2 + 2 * i] = digits[bytes[i] >> 4];
    out[3 + 2 * i] = digits[bytes[i] & 15];
  }
  return out;
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

class PgConnection;

class PgStatement : public StatementBackend {
 public:
  PgStatement(PgConnection& db, const std::string& sql);
  void bindInt(int index, int64_t value) override { slot(index) = std::to_string(value); }
  void bindDouble(int index, double value) override;
  void bindText(int index, const std::string& value) override { slot(index) = value; }
  void bindBlob(int index, const std::vector<uint8_t>& value) override { slot(index) = hexBytea(value); }
  void bindNull(int index) override { slot(index).reset(); }
  bool step() override;
  void reset() override {
    executed_ = false;
    row_ = -1;
    result_ = pqxx::result();
    for (auto& p : params_) p.reset();
  }
  int columnCount() const override;
  std::string columnName(int c) const override { return result_.column_name(static_cast<pqxx::row::size_type>(c)); }
  bool isNull(int c) const override { return field(c).is_null(); }
  bool isInteger(int c) const override {
    const pqxx::oid t = type(c);
    return !isNull(c) && (t == kInt8 || t == kInt4 || t == kInt2 || t == kBool);
  }
  bool isFloat(int c) const override {
    const pqxx::oid t = type(c);
    return !isNull(c) && (t == kFloat8 || t == kFloat4 || t == kNumeric);
  }
  bool isBlob(int c) const override { return !isNull(c) && type(c) == kBytea; }
  int64_t columnInt(int c) const override;
  double columnDouble(int c) const override;
  std::string columnText(int c) const override {
    const pqxx::field f = field(c);
    return f.is_null() ? std::string() : std::string(f.c_str(), f.size());
  }
  std::vector<uint8_t> columnBlob(int c) const override;

 private:
  std::optional<std::string>& slot(int index);
  pqxx::field field(int c) const;
  pqxx::oid type(int c) const { return result_.column_type(static_cast<pqxx::row::size_type>(c)); }

  PgConnection* db_;
  std::string sql_;
  std::vector<std::optional<std::string>> params_;
  // The result, fetched whole at the first step() (or columnCount()).
  mutable pqxx::result result_;
  mutable bool executed_ = false;
  mutable long row_ = -1;
};

class PgConnection : public ConnectionBackend {
 public:
  PgConnection(const std::string& url, const std::string& shown_as, const OpenOptions& options)
      : name_(shown_as), read_only_(options.read_only) {
    try {
      conn_ = std::make_unique<pqxx::connection>(url);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
      // Never reconnect behind our back: a transaction's statements must not
      // continue on a new session as if the old one had not been lost.
      conn_->inhibit_reactivation(true);
#pragma GCC diagnostic pop
      // extra_float_digits=3: every double comes back exactly (shortest round-trip
      // text on PostgreSQL 12+); lock_timeout: the busy timeout;
      // client_min_messages: no NOTICE on stderr.
      exec("SET extra_float_digits = 3; SET client_min_messages = warning; SET lock_timeout = " +
           std::to_string(options.busy_timeout_ms) + (read_only_ ? "; SET default_transaction_read_only = on" : ""));
    } catch (const DatabaseError&) {
      throw;
    } catch (const pqxx::broken_connection& e) {
      throw DatabaseError("[Database] " + name_ + ": cannot connect: " + oneLine(e.what()));
    } catch (const pqxx::failure&) {
      rethrow("Database", name_);
    }
  }
  Backend kind() const override { return Backend::PostgreSQL; }

  void exec(const std::string& sql) override {
    try {
      pqxx::nontransaction w(*conn_);
      w.exec(sql);
      w.commit();
    } catch (const pqxx::failure&) {
      rethrow("Database::exec", name_);
    }
  }
  std::unique_ptr<StatementBackend> prepare(const std::string& sql) override {
    return std::make_unique<PgStatement>(*this, sql);
  }
  pqxx::result run(const std::string& sql, const std::vector<std::optional<std::string>>& params, const char* what) {
    std::vector<const char*> values;
    values.reserve(params.size());
    for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
    try {
      pqxx::nontransaction w(*conn_);
      pqxx::result r = w.exec_params(sql, pqxx::prepare::make_dynamic_params(values));
      w.commit();
      return r;
    } catch (const pqxx::failure&) {
      rethrow(what, name_);
    }
  }
  int64_t lastInsertId() override { return run("SELECT lastval()", {}, "Database::lastInsertId")[0][0].as<int64_t>(); }
  bool readOnly() const override { return read_only_; }
  int userVersion() override {
    const pqxx::result r = run("SELECT to_regclass('sailshape_schema') IS NOT NULL", {}, "Database::userVersion");
    if (!r[0][0].as<bool>()) return 0;
    const pqxx::result v = run("SELECT max(version) FROM sailshape_schema", {}, "Database::userVersion");
    return v[0][0].is_null() ? 0 : v[0][0].as<int>();
  }
  void setUserVersion(int version) override {
    exec("CREATE TABLE IF NOT EXISTS sailshape_schema (version BIGINT NOT NULL); DELETE FROM sailshape_schema;"
         " INSERT INTO sailshape_schema VALUES (" + std::to_string(version) + ")");
  }
  int64_t tableCount() override {
    return run("SELECT count(*) FROM pg_catalog.pg_tables WHERE schemaname = current_schema()"
               " AND tablename <> 'sailshape_schema'", {}, "Database::tableCount")[0][0].as<int64_t>();
  }
  std::vector<std::string> integrityCheck() override;
  void backupTo(const std::string&) override {
    throw DatabaseError("[Database::backupTo] " + name_ +
                        ": backup copies an SQLite file; copy a PostgreSQL store with `sailshape db copy` (or pg_dump)");
  }
  void begin() override { exec("BEGIN ISOLATION LEVEL SERIALIZABLE"); }
  void commit() override { exec("COMMIT"); }
  void beginSnapshot() override { exec("BEGIN ISOLATION LEVEL REPEATABLE READ, READ ONLY"); }
  void rollback() noexcept override {
    try {
      if (conn_->is_open()) exec("ROLLBACK");
    } catch (...) {
      // A lost connection has no transaction left to roll back: the server did it.
    }
  }
  void lockSchema(bool lock) override {
    exec(std::string(lock ? "SELECT pg_advisory_lock(" : "SELECT pg_advisory_unlock(") + std::to_string(kSchemaLockKey) + ")");
  }
  void enableConcurrentReaders() override {}
  const std::string& name() const { return name_; }

 private:
  std::unique_ptr<pqxx::connection> conn_;
  std::string name_;
  bool read_only_ = false;
};

std::vector<std::string> PgConnection::integrityCheck() {
  std::vector<std::string> problems;
  // Every single-column foreign key of the schema: rows whose referent is missing.
  const pqxx::result keys = run(
      "SELECT c.conrelid::regclass::text, a.attname, c.confrelid::regclass::text, af.attname FROM pg_constraint c"
      " JOIN pg_attribute a ON a.attrelid = c.conrelid AND a.attnum = c.conkey[1]"
      " JOIN pg_attribute af ON af.attrelid = c.confrelid AND af.attnum = c.confkey[1]"
      " WHERE c.contype = 'f' AND c.connamespace = current_schema()::regnamespace ORDER BY 1, 2",
      {}, "Database::integrityCheck");
  for (const auto& k : keys) {
    const std::string child = k[0].c_str(), column = k[1].c_str(), parent = k[2].c_str(), key = k[3].c_str();
    const pqxx::result n = run("SELECT count(*) FROM " + child + " x WHERE x." + column + " IS NOT NULL AND NOT EXISTS"
                               " (SELECT 1 FROM " + parent + " p WHERE p." + key + " = x." + column + ")",
                               {}, "Database::integrityCheck");
    const int64_t orphans = n[0][0].as<int64_t>();
    if (orphans > 0)
      problems.push_back("foreign key: " + std::to_string(orphans) + " rows of " + child + " refer to a missing row of " +
                         parent);
  }
  return problems;
}

PgStatement::PgStatement(PgConnection& db, const std::string& sql) : db_(&db) {
  int n = 0;
  sql_ = numberPlaceholders(sql, &n);
  params_.resize(static_cast<size_t>(n));
}

std::optional<std::string>& PgStatement::slot(int index) {
  if (index < 1 || index > static_cast<int>(params_.size()))
    throw DatabaseError("[Statement::bind] " + db_->name() + ": parameter " + std::to_string(index) +
                        " out of range (the statement has " + std::to_string(params_.size()) + ")");
  return params_[static_cast<size_t>(index - 1)];
}

void PgStatement::bindDouble(int index, double value) {
  if (std::isnan(value)) {
    slot(index).reset();  // as SQLite stores NaN: NULL
    return;
  }
  if (std::isinf(value)) {
    slot(index) = value > 0 ? "Infinity" : "-Infinity";
    return;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);  // round-trips
  slot(index) = buf;
}

bool PgStatement::step() {
  if (!executed_) {
    result_ = db_->run(sql_, params_, "Statement::step");
    executed_ = true;
    row_ = -1;
  }
  ++row_;
  return row_ < static_cast<long>(result_.size());
}

int PgStatement::columnCount() const {
  if (!executed_) {
    // SQLite knows a statement's columns before it runs; callers ask first.
    result_ = db_->run(sql_, params_, "Statement::columnCount");
    executed_ = true;
    row_ = -1;
  }
  return static_cast<int>(result_.columns());
}

pqxx::field PgStatement::field(int c) const {
  if (row_ < 0 || row_ >= static_cast<long>(result_.size()))
    throw DatabaseError("[Statement::column] " + db_->name() + ": no current row");
  return result_[static_cast<pqxx::result::size_type>(row_)][static_cast<pqxx::row::size_type>(c)];
}

int64_t PgStatement::columnInt(int c) const {
  const pqxx::field f = field(c);
  if (f.is_null()) return 0;
  if (type(c) == kBool) return f.c_str()[0] == 't' ? 1 : 0;
  if (isFloat(c)) return static_cast<int64_t>(columnDouble(c));
  return std::strtoll(f.c_str(), nullptr, 10);
}

double PgStatement::columnDouble(int c) const {
  const pqxx::field f = field(c);
  if (f.is_null()) return 0;
  return std::strtod(f.c_str(), nullptr);  // also reads "NaN", "Infinity", "-Infinity"
}

std::vector<uint8_t> PgStatement::columnBlob(int c) const {
  const pqxx::field f = field(c);
  if (f.is_null()) return {};
  const char* s = f.c_str();
  const size_t n = f.size();
  if (type(c) != kBytea || n < 2 || s[0] != '\\' || s[1] != 'x') return std::vector<uint8_t>(s, s + n);
  std::vector<uint8_t> out((n - 2) / 2);
  for (size_t i = 0; i < out.size(); ++i) {
    const int hi = hexDigit(s[2 + 2 * i]), lo = hexDigit(s[3 + 2 * i]);
    if (hi < 0 || lo < 0) throw DatabaseError("[Statement::columnBlob] " + db_->name() + ": malformed bytea text");
    out[i] = static_cast<uint8_t>(hi << 4 | lo);
  }
  return out;
}

}  // namespace

std::unique_ptr<ConnectionBackend> openPostgres(const std::string& url, const std::string& shown_as,
                                                const OpenOptions& options) {
  return std::make_unique<PgConnection>(url, shown_as, options);
}

}  // namespace sailshape::detail
