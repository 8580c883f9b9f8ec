#pragma once
// What each backend of the store implements (database/ only; store.hpp's
// Database and Statement forward to these).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "database/store.hpp"

namespace sailshape::detail {

class StatementBackend {
 public:
  virtual ~StatementBackend() = default;
  virtual void bindInt(int index, int64_t value) = 0;
  virtual void bindDouble(int index, double value) = 0;
  virtual void bindText(int index, const std::string& value) = 0;
  virtual void bindBlob(int index, const std::vector<uint8_t>& value) = 0;
  virtual void bindNull(int index) = 0;
  virtual bool step() = 0;
  virtual void reset() = 0;
  virtual int columnCount() const = 0;
  virtual std::string columnName(int column) const = 0;
  virtual bool isNull(int column) const = 0;
  virtual bool isInteger(int column) const = 0;
  virtual bool isFloat(int column) const = 0;
  virtual bool isBlob(int column) const = 0;
  virtual int64_t columnInt(int column) const = 0;
  virtual double columnDouble(int column) const = 0;
  virtual std::string columnText(int column) const = 0;
  virtual std::vector<uint8_t> columnBlob(int column) const = 0;
};

class ConnectionBackend {
 public:
  virtual ~ConnectionBackend() = default;
  virtual Backend kind() const = 0;
  virtual void exec(const std::string& sql) = 0;
  virtual std::unique_ptr<StatementBackend> prepare(const std::string& sql) = 0;
  virtual int64_t lastInsertId() = 0;
  virtual bool readOnly() const = 0;
  virtual int userVersion() = 0;
  virtual void setUserVersion(int version) = 0;
  virtual int64_t tableCount() = 0;
  virtual std::vector<std::string> integrityCheck() = 0;
  virtual void backupTo(const std::string& dest_path) = 0;
  virtual void begin() = 0;
  virtual void commit() = 0;
  virtual void rollback() noexcept = 0;
  virtual void beginSnapshot() = 0;
  virtual void lockSchema(bool lock) = 0;
  virtual void enableConcurrentReaders() = 0;
};

std::unique_ptr<ConnectionBackend> openSqlite(const std::string& path, const OpenOptions& options);
std::unique_ptr<ConnectionBackend> openPostgres(const std::string& url, const std::string& shown_as,
                                                const OpenOptions& options);

}  // namespace sailshape::detail
