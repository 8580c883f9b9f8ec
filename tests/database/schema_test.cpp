#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>

#include "database/schema.hpp"
#include "database/sqlite.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::TempDir;

int64_t count(Database& db, const std::string& table) {
  Statement s = db.prepare("SELECT count(*) FROM " + table);
  s.step();
  return s.columnInt(0);
}

bool hasTable(Database& db, const std::string& name) {
  Statement s = db.prepare("SELECT count(*) FROM sqlite_schema WHERE name = ?");
  s.bind(1, name).step();
  return s.columnInt(0) == 1;
}

TEST(Schema, NewDatabaseIsAtCurrentVersionWithWalAndForeignKeys) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  EXPECT_EQ(db.userVersion(), kSchemaVersion);
  Statement j = db.prepare("PRAGMA journal_mode");
  j.step();
  EXPECT_EQ(j.columnText(0), "wal");
  Statement fk = db.prepare("PRAGMA foreign_keys");
  fk.step();
  EXPECT_EQ(fk.columnInt(0), 1);
  for (const char* t : {"campaigns", "boats", "sails", "scanner_units", "calibrations", "sessions", "scans",
                        "registrations", "trim_steps", "control_settings", "pressures", "analyses", "sections",
                        "design_comparisons", "design_versions"})
    EXPECT_TRUE(hasTable(db, t)) << t;
  EXPECT_TRUE(db.integrityCheck().empty());
  // Foreign keys are enforced.
  EXPECT_THROW(db.exec("INSERT INTO sessions(campaign_id, name) VALUES (999, 'x')"), DatabaseError);
}

TEST(Schema, MigratesFromEveryOlderVersionKeepingData) {
  for (int from = 0; from < kSchemaVersion; ++from) {
    TempDir dir;
    const std::string path = dir.file("old.db");
    {
      Database db(path);
      migrateSchema(db, from);
      EXPECT_EQ(db.userVersion(), from);
      if (from >= 1) db.exec("INSERT INTO campaigns(name, kind) VALUES ('Lorient 2025', 'full_scale')");
    }
    Database db = openSailDatabase(path);
    EXPECT_EQ(db.userVersion(), kSchemaVersion) << "from " << from;
    EXPECT_TRUE(hasTable(db, "design_comparisons")) << "from " << from;
    EXPECT_TRUE(hasTable(db, "design_versions")) << "from " << from;
    Statement idx = db.prepare("SELECT count(*) FROM sqlite_schema WHERE type = 'index' AND name = 'trim_steps_sail_awa'");
    idx.step();
    EXPECT_EQ(idx.columnInt(0), 1) << "from " << from;
    if (from >= 1) {
      EXPECT_EQ(count(db, "campaigns"), 1) << "from " << from;
    }
    EXPECT_TRUE(db.integrityCheck().empty());
  }
}

TEST(Schema, MigrationTargetOutsideRangeThrows) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  EXPECT_THROW(migrateSchema(db, kSchemaVersion + 1), DatabaseError);
  EXPECT_THROW(migrateSchema(db, 1), DatabaseError);
}

TEST(Schema, NewerVersionIsRefusedNotDowngraded) {
  TempDir dir;
  const std::string path = dir.file("new.db");
  {
    Database db = openSailDatabase(path);
    db.setUserVersion(kSchemaVersion + 1);
  }
  try {
    openSailDatabase(path);
    FAIL() << "expected DatabaseError";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("database schema version " + std::to_string(kSchemaVersion + 1) +
                                         " is newer than this sailshape (" + std::to_string(kSchemaVersion) + ")"),
              std::string::npos)
        << e.what();
  }
  Database raw(path);
  EXPECT_EQ(raw.userVersion(), kSchemaVersion + 1);
  EXPECT_THROW(migrateSchema(raw), DatabaseError);
}

TEST(Schema, NonDatabaseFileIsRefusedAndLeftByteIdentical) {
  TempDir dir;
  const std::string path = dir.file("notes.db");
  {
    std::ofstream out(path, std::ios::binary);
    for (int i = 0; i < 2000; ++i) out << "tack height 1.2 m, sheet 0.4 m, line " << i << "\n";
  }
  const std::string before = test::readBytes(path);
  try {
    openSailDatabase(path);
    FAIL() << "expected DatabaseError";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("not an SQLite database"), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::readBytes(path), before);
  EXPECT_FALSE(std::filesystem::exists(path + "-wal"));
}

TEST(Schema, ForeignSqliteDatabaseIsRefused) {
  TempDir dir;
  const std::string path = dir.file("other.db");
  {
    Database db(path);
    db.exec("CREATE TABLE photos(id INTEGER PRIMARY KEY)");
  }
  const std::string before = test::readBytes(path);
  EXPECT_THROW(openSailDatabase(path), DatabaseError);
  EXPECT_EQ(test::readBytes(path), before);  // not even switched to WAL
  EXPECT_FALSE(std::filesystem::exists(path + "-wal"));
  Database db(path);
  EXPECT_EQ(db.userVersion(), 0);
}

TEST(Schema, DamagedDatabaseGivesClearErrorAndIsNotOverwritten) {
  TempDir dir;
  const std::string path = dir.file("damaged.db");
  {
    Database db = openSailDatabase(path);
    db.exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  std::string bytes = test::readBytes(path);
  ASSERT_GT(bytes.size(), 4096u);
  // Destroy the header's magic string: SQLite no longer recognises the file.
  for (int i = 0; i < 16; ++i) bytes[i] = 'X';
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_THROW(openSailDatabase(path), DatabaseError);
  EXPECT_EQ(test::readBytes(path), bytes);
}

TEST(Schema, DamagedPagesAreReportedAndTheFileIsNotOverwritten) {
  TempDir dir;
  const std::string path = dir.file("damaged-pages.db");
  {
    Database db = openSailDatabase(path);
    Transaction tx(db);
    Statement s = db.prepare("INSERT INTO boats(name, notes) VALUES (?, ?)");
    for (int i = 0; i < 400; ++i) {
      s.bind(1, "boat " + std::to_string(i)).bind(2, std::string(200, 'n')).run();
      s.reset();
    }
    tx.commit();
    db.exec("PRAGMA wal_checkpoint(TRUNCATE)");
  }
  std::string bytes = test::readBytes(path);
  ASSERT_GT(bytes.size(), 20u * 4096);
  // Garbage over two pages in the middle of the boats table's b-tree.
  for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 8192; ++i) bytes[i] = char(0xA5);
  { std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes; }
  bool reported = false;
  try {
    Database db = openSailDatabase(path);
    reported = !db.integrityCheck().empty();
  } catch (const DatabaseError& e) {
    reported = std::string(e.what()).find("damaged") != std::string::npos;
  }
  EXPECT_TRUE(reported);
  EXPECT_EQ(test::readBytes(path), bytes);
}

TEST(Schema, MissingFileWithoutCreateThrows) {
  TempDir dir;
  OpenOptions o;
  o.create = false;
  EXPECT_THROW(openSailDatabase(dir.file("missing.db"), o), DatabaseError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("missing.db")));
}

TEST(Schema, NegativeBusyTimeoutThrows) {
  TempDir dir;
  OpenOptions o;
  o.busy_timeout_ms = -1;
  EXPECT_THROW(Database(dir.file("a.db"), o), DatabaseError);
}

TEST(Sqlite, TransactionRollsBackUnlessCommitted) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  {
    Transaction tx(db);
    db.exec("INSERT INTO boats(name) VALUES ('Pen Duick')");
  }
  EXPECT_EQ(count(db, "boats"), 0);
  {
    Transaction tx(db);
    db.exec("INSERT INTO boats(name) VALUES ('Pen Duick')");
    tx.commit();
  }
  EXPECT_EQ(count(db, "boats"), 1);
  EXPECT_THROW(db.exec("INSERT INTO nowhere VALUES (1)"), DatabaseError);
  EXPECT_THROW(db.prepare("SELEC 1"), DatabaseError);
}

TEST(Sqlite, LockedDatabaseWaitsThenFailsClearly) {
  TempDir dir;
  const std::string path = dir.file("a.db");
  Database holder = openSailDatabase(path);
  Transaction held(holder);
  holder.exec("INSERT INTO boats(name) VALUES ('holder')");

  OpenOptions o;
  o.busy_timeout_ms = 300;
  Database other = openSailDatabase(path, o);
  const auto start = std::chrono::steady_clock::now();
  try {
    Transaction tx(other);
    FAIL() << "expected DatabaseBusy";
  } catch (const DatabaseBusy& e) {
    EXPECT_NE(std::string(e.what()).find("database is locked by another connection (waited 300 ms)"), std::string::npos)
        << e.what();
  }
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(waited, 0.25);
  held.commit();
  Transaction tx(other);  // free again
  tx.commit();
}

TEST(Sqlite, ReaderKeepsReadingWhileWriterWrites) {
  TempDir dir;
  const std::string path = dir.file("a.db");
  Database writer = openSailDatabase(path);
  writer.exec("INSERT INTO boats(name) VALUES ('first')");
  Database reader = openSailDatabase(path);
  Transaction tx(writer);
  writer.exec("INSERT INTO boats(name) VALUES ('second')");
  // WAL: the reader sees the last commit without waiting for the writer.
  EXPECT_EQ(count(reader, "boats"), 1);
  tx.commit();
  EXPECT_EQ(count(reader, "boats"), 2);
}

TEST(Sqlite, BackupHasIdenticalContent) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  db.exec("INSERT INTO boats(name, class) VALUES ('A', 'J/80'), ('B', 'Figaro 3')");
  db.backupTo(dir.file("copy.db"));
  Database copy = openSailDatabase(dir.file("copy.db"));
  EXPECT_EQ(copy.userVersion(), kSchemaVersion);
  EXPECT_TRUE(copy.integrityCheck().empty());
  Statement a = db.prepare("SELECT name, class FROM boats ORDER BY id");
  Statement b = copy.prepare("SELECT name, class FROM boats ORDER BY id");
  int rows = 0;
  while (a.step()) {
    ASSERT_TRUE(b.step());
    EXPECT_EQ(a.columnText(0), b.columnText(0));
    EXPECT_EQ(a.columnText(1), b.columnText(1));
    ++rows;
  }
  EXPECT_FALSE(b.step());
  EXPECT_EQ(rows, 2);
  EXPECT_THROW(db.backupTo(dir.file("no/such/dir/copy.db")), DatabaseError);
}

}  // namespace
}  // namespace sailshape
