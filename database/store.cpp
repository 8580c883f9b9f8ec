#include "database/store.hpp"

#include <chrono>
#include <random>
#include <thread>
#include <utility>

#include "database/backend.hpp"
#include "database/dialect.hpp"

namespace sailshape {

bool isPostgresUrl(const std::string& location) {
  return location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0;
}

Database::Database(const std::string& location, const OpenOptions& options)
    : path_(detail::redactedLocation(location)), busy_timeout_ms_(options.busy_timeout_ms) {
  if (options.busy_timeout_ms < 0)
    throw DatabaseError("[Database] busy_timeout_ms must be >= 0 (got " + std::to_string(options.busy_timeout_ms) + ")");
  impl_ = isPostgresUrl(location) ? detail::openPostgres(location, path_, options) : detail::openSqlite(location, options);
}

Database::~Database() = default;
Database::Database(Database&& other) noexcept = default;
Database& Database::operator=(Database&& other) noexcept = default;

Backend Database::backend() const { return impl_->kind(); }
void Database::exec(const std::string& sql) { impl_->exec(sql); }
Statement Database::prepare(const std::string& sql) { return Statement(*this, sql); }
int64_t Database::lastInsertId() const { return impl_->lastInsertId(); }
bool Database::readOnly() const { return impl_->readOnly(); }
int Database::userVersion() { return impl_->userVersion(); }
void Database::setUserVersion(int version) { impl_->setUserVersion(version); }
int64_t Database::tableCount() { return impl_->tableCount(); }
std::vector<std::string> Database::integrityCheck() { return impl_->integrityCheck(); }
void Database::backupTo(const std::string& dest_path) { impl_->backupTo(dest_path); }
void Database::begin() { impl_->begin(); }
void Database::commit() { impl_->commit(); }
void Database::rollback() noexcept { impl_->rollback(); }
void Database::beginSnapshot() { impl_->beginSnapshot(); }
void Database::lockSchema(bool lock) { impl_->lockSchema(lock); }
void Database::enableConcurrentReaders() { impl_->enableConcurrentReaders(); }

Statement::Statement(Database& db, const std::string& sql) : impl_(db.connection().prepare(sql)) {}
Statement::~Statement() = default;
Statement::Statement(Statement&& other) noexcept = default;

Statement& Statement::bind(int index, int64_t value) {
  impl_->bindInt(index, value);
  return *this;
}
Statement& Statement::bind(int index, double value) {
  impl_->bindDouble(index, value);
  return *this;
}
Statement& Statement::bind(int index, const std::string& value) {
  impl_->bindText(index, value);
  return *this;
}
Statement& Statement::bind(int index, const std::optional<double>& value) {
  return value ? bind(index, *value) : bindNull(index);
}
Statement& Statement::bindBlob(int index, const std::vector<uint8_t>& value) {
  impl_->bindBlob(index, value);
  return *this;
}
Statement& Statement::bindNull(int index) {
  impl_->bindNull(index);
  return *this;
}

bool Statement::step() { return impl_->step(); }
void Statement::run() {
  while (step()) {
  }
}
void Statement::reset() { impl_->reset(); }
int Statement::columnCount() const { return impl_->columnCount(); }
std::string Statement::columnName(int c) const { return impl_->columnName(c); }
bool Statement::isNull(int c) const { return impl_->isNull(c); }
bool Statement::isInteger(int c) const { return impl_->isInteger(c); }
bool Statement::isFloat(int c) const { return impl_->isFloat(c); }
bool Statement::isBlob(int c) const { return impl_->isBlob(c); }
int64_t Statement::columnInt(int c) const { return impl_->columnInt(c); }
double Statement::columnDouble(int c) const { return impl_->columnDouble(c); }
std::string Statement::columnText(int c) const { return impl_->columnText(c); }
std::vector<uint8_t> Statement::columnBlob(int c) const { return impl_->columnBlob(c); }

Transaction::Transaction(Database& db) : db_(db) { db_.begin(); }

Transaction::~Transaction() {
  if (!done_) db_.rollback();
}

void Transaction::commit() {
  db_.commit();
  done_ = true;
}

int runTransaction(Database& db, const std::function<void()>& body, int max_attempts) {
  if (max_attempts < 1)
    throw DatabaseError("[runTransaction] max_attempts must be >= 1 (got " + std::to_string(max_attempts) + ")");
  std::minstd_rand jitter(std::random_device{}());
  for (int attempt = 1;; ++attempt) {
    try {
      Transaction tx(db);
      body();
      tx.commit();
      return attempt;
    } catch (const SerializationFailure&) {
      if (attempt >= max_attempts) throw;
    }
    // Writers that collided wait different whiles, so the next round differs:
    // up to 5 ms at first, doubling to 320 ms.
    const int ceiling_ms = 5 << std::min(attempt - 1, 6);
    std::this_thread::sleep_for(std::chrono::microseconds(jitter() % (ceiling_ms * 1000)));
  }
}

}  // namespace sailshape
