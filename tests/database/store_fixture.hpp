#pragma once
// The database suite over both backends: a test of StoreTest runs once on an
// SQLite file and once on a database of the private PostgreSQL cluster
// (pg_cluster.hpp). Without a cluster the PostgreSQL instance fails, naming why.
#include <gtest/gtest.h>

#include <string>

#include "database/store.hpp"
#include "db_fixture.hpp"
#include "pg_cluster.hpp"

namespace sailshape::test {

class StoreTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (GetParam() == Backend::PostgreSQL) {
      try {
        PgCluster::shared();
      } catch (const std::exception& e) {
        FAIL() << e.what();
      }
    }
    location_ = newLocation();
  }
  // A new, empty store of this test's backend.
  std::string newLocation() {
    if (GetParam() == Backend::PostgreSQL) return PgCluster::shared().createDatabase();
    return dir_.file("store" + std::to_string(++stores_) + ".db");
  }
  TempDir dir_;
  std::string location_;
  int stores_ = 0;
};

inline std::string backendName(const ::testing::TestParamInfo<Backend>& info) {
  return info.param == Backend::SQLite ? "SQLite" : "PostgreSQL";
}

inline int64_t scalar(Database& db, const std::string& sql) {
  Statement s = db.prepare(sql);
  s.step();
  return s.columnInt(0);
}

}  // namespace sailshape::test
