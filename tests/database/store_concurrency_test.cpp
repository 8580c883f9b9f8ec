// Many writers at once on both backends: concurrent importers in separate
// processes, some killed mid-import; readers beside a writer; and, on
// PostgreSQL, a retried serialization failure and a lost connection.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <thread>

#include "analysis/core/errors.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/schema.hpp"
#include "store_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::scalar;

// Own fixture name, so these cases are instantiated here only.
class StoreConcurrency : public test::StoreTest {};

constexpr int kImporters = 8;  // finish their import
constexpr int kKilled = 4;     // SIGKILLed with every row written, before the commit

ImportMetadata stepMeta(int step) {
  ImportMetadata m;
  m.campaign = "Loft";  // one campaign, boat and sail for all: their rows are created by whoever comes first
  m.boat = "Alpha";
  m.sail = "Gen-A";
  m.sail_type = "genoa";
  m.test = "concurrent";
  m.trim_step = step;
  m.awa_deg = 60.0 + step;
  m.controls = {{"sheet", 0.1 * step}};
  return m;
}

Cloud cloudOf(int n, unsigned seed) {
  Cloud c;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i) c.points.emplace_back(u(rng), u(rng), u(rng));
  return c;
}

// The child's whole life: open its own connection, import step `step` (a
// killed one stops in the middle and tells the parent through `ready`).
[[noreturn]] void importer(const std::string& location, int step, int ready) {
  try {
    OpenOptions o;
    o.busy_timeout_ms = 60000;  // SQLite: wait while the killed writers hold the lock
    Database db = openSailDatabase(location, o);
    const nlohmann::json doc = analysisDoc(8.0 + step);
    const Cloud cloud = cloudOf(20000, 100 + step);
    importScan(db, stepMeta(step), &doc, &cloud, [&](const std::string& stage) {
      if (ready < 0 || stage != "sections") return;
      const char c = 'k';
      if (write(ready, &c, 1) != 1) _exit(3);
      for (;;) pause();
    });
  } catch (const std::exception& e) {
    std::fprintf(stderr, "importer %d: %s\n", step, e.what());
    _exit(2);
  }
  _exit(0);
}

TEST_P(StoreConcurrency, ConcurrentImportersAndKilledOnesLeaveOnlyWholeImports) {
  { Database db = openSailDatabase(location_); }  // the schema; closed before fork, no connection crosses it
  std::vector<pid_t> pids;
  std::vector<int> pipes;  // read ends of the killed ones' pipes
  for (int i = 0; i < kImporters + kKilled; ++i) {
    int fds[2] = {-1, -1};
    const bool killed = i >= kImporters;
    if (killed) ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      if (killed) close(fds[0]);
      importer(location_, i, killed ? fds[1] : -1);
    }
    pids.push_back(pid);
    if (killed) {
      close(fds[1]);
      pipes.push_back(fds[0]);
    }
  }
  // Kill each stopped writer as soon as it says it is in the middle (SQLite:
  // it holds the write lock the others wait for).
  int killed = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
  std::vector<bool> done(pipes.size(), false);
  while (killed < kKilled && std::chrono::steady_clock::now() < deadline) {
    std::vector<pollfd> p;
    for (size_t k = 0; k < pipes.size(); ++k)
      if (!done[k]) p.push_back({pipes[k], POLLIN, 0});
    ASSERT_GE(poll(p.data(), p.size(), 1000), 0);
    for (const pollfd& q : p) {
      if (!(q.revents & (POLLIN | POLLHUP))) continue;
      const size_t k = static_cast<size_t>(std::find(pipes.begin(), pipes.end(), q.fd) - pipes.begin());
      char c = 0;
      EXPECT_EQ(read(q.fd, &c, 1), 1) << "killed importer " << k << " ended before the middle of its import";
      ASSERT_EQ(kill(pids[kImporters + k], SIGKILL), 0);
      done[k] = true;
      ++killed;
    }
  }
  for (int fd : pipes) close(fd);
  EXPECT_EQ(killed, kKilled) << "not every importer to kill reached the middle of its import in 90 s";
  for (size_t i = 0; i < pids.size(); ++i) {
    int status = 0;
    if (i >= static_cast<size_t>(kImporters) && killed < kKilled) kill(pids[i], SIGKILL);
    ASSERT_EQ(waitpid(pids[i], &status, 0), pids[i]);
    if (i < static_cast<size_t>(kImporters)) {
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "importer " << i << " failed (its stderr says why)";
    } else {
      EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "importer " << i;
    }
  }

  Database db = openSailDatabase(location_);
  EXPECT_TRUE(db.integrityCheck().empty());  // what `db check` reports
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans"), kImporters);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM campaigns"), 1);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM sails"), 1);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM trim_steps"), kImporters);
  EXPECT_EQ(scalar(db, "SELECT max(step_order) FROM trim_steps"), kImporters - 1);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM control_settings"), kImporters);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM analyses"), kImporters);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM sections"), 3 * kImporters);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans WHERE point_count = 20000 AND cloud IS NOT NULL"), kImporters);
  // Each whole: its step's camber at mid-height is 8 + step + 1.
  const Table evolution = parameterEvolution(db, "concurrent", "camber_pct", 0.5);
  ASSERT_EQ(evolution.rows.size(), static_cast<size_t>(kImporters));
  for (int step = 0; step < kImporters; ++step) {
    EXPECT_EQ(std::get<int64_t>(evolution.rows[step][0]), step);
    EXPECT_DOUBLE_EQ(std::get<double>(evolution.rows[step][5]), 9.0 + step);
  }
}

TEST_P(StoreConcurrency, ReadersKeepReadingWhileAWriterWrites) {
  Database writer = openSailDatabase(location_);
  const nlohmann::json doc = analysisDoc(8.0);
  importScan(writer, stepMeta(0), &doc);
  OpenOptions quick;
  quick.busy_timeout_ms = 100;
  Database reader = openSailDatabase(location_, quick);
  size_t seen_during = 0;
  importScan(writer, stepMeta(1), &doc, nullptr, [&](const std::string& stage) {
    if (stage == "sections") seen_during = findScans(reader).rows.size();  // the writer holds its transaction open
  });
  EXPECT_EQ(seen_during, 1u);
  EXPECT_EQ(findScans(reader).rows.size(), 2u);
}

TEST_P(StoreConcurrency, StoresOpenedFirstByManyAtOnceAreMigratedOnce) {
  constexpr int kOpeners = 6;  // threads, each with its own connection
  std::vector<std::thread> threads;
  std::vector<std::string> errors(kOpeners);
  for (int i = 0; i < kOpeners; ++i)
    threads.emplace_back([&, i] {
      try {
        OpenOptions o;
        o.busy_timeout_ms = 30000;
        Database db = openSailDatabase(location_, o);
        if (db.userVersion() != kSchemaVersion) errors[i] = "version " + std::to_string(db.userVersion());
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    });
  for (auto& t : threads) t.join();
  for (int i = 0; i < kOpeners; ++i) EXPECT_EQ(errors[i], "") << "opener " << i;
  Database db = openSailDatabase(location_);
  EXPECT_EQ(db.tableCount(), 15);
  EXPECT_TRUE(db.integrityCheck().empty());
}

INSTANTIATE_TEST_SUITE_P(Backends, StoreConcurrency, ::testing::Values(Backend::SQLite, Backend::PostgreSQL), test::backendName);

class PostgreSQLStore : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      url_ = test::PgCluster::shared().createDatabase();
    } catch (const std::exception& e) {
      FAIL() << e.what();
    }
  }
  std::string url_;
};

TEST_F(PostgreSQLStore, ASerializationFailureIsRetriedWithTheOtherWritersChangeSeen) {
  Database a = openSailDatabase(url_);
  Database b(url_);
  a.exec("INSERT INTO campaigns(name, notes) VALUES ('c', '0')");
  int runs = 0;
  const int attempts = runTransaction(a, [&] {
    ++runs;
    Statement s = a.prepare("SELECT notes FROM campaigns WHERE name = 'c'");
    ASSERT_TRUE(s.step());
    const std::string seen = s.columnText(0);
    // Another writer changes the row after this transaction's snapshot.
    if (runs == 1) b.exec("UPDATE campaigns SET notes = notes || '+b' WHERE name = 'c'");
    a.prepare("UPDATE campaigns SET notes = ? WHERE name = 'c'").bind(1, seen + "+a").run();
  });
  EXPECT_EQ(attempts, 2);
  EXPECT_EQ(runs, 2);
  Statement s = a.prepare("SELECT notes FROM campaigns WHERE name = 'c'");
  ASSERT_TRUE(s.step());
  EXPECT_EQ(s.columnText(0), "0+b+a");

  // With no attempt left, the failure reaches the caller and nothing is stored.
  runs = 0;
  EXPECT_THROW(runTransaction(
                   a,
                   [&] {
                     ++runs;
                     Statement r = a.prepare("SELECT notes FROM campaigns WHERE name = 'c'");
                     r.step();
                     b.exec("UPDATE campaigns SET notes = 'b' WHERE name = 'c'");
                     a.exec("UPDATE campaigns SET notes = 'a' WHERE name = 'c'");
                   },
                   1),
               SerializationFailure);
  EXPECT_EQ(runs, 1);
  Statement t = a.prepare("SELECT notes FROM campaigns WHERE name = 'c'");
  ASSERT_TRUE(t.step());
  EXPECT_EQ(t.columnText(0), "b");
}

TEST_F(PostgreSQLStore, ALostConnectionIsOneClearErrorAndStoresNothing) {
  Database db = openSailDatabase(url_);
  Database admin(url_);
  const int64_t pid = scalar(db, "SELECT pg_backend_pid()");
  const nlohmann::json doc = analysisDoc(8.0);
  try {
    importScan(db, stepMeta(0), &doc, nullptr, [&](const std::string& stage) {
      if (stage == "scan") admin.exec("SELECT pg_terminate_backend(" + std::to_string(pid) + ")");
    });
    ADD_FAILURE() << "the import went on after its connection was terminated";
  } catch (const ConnectionLost& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find("lost the connection to the PostgreSQL server; nothing of the open transaction was stored"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("127.0.0.1"), std::string::npos) << what;
  }
  EXPECT_THROW(findScans(db), ConnectionLost);  // no silent reconnect
  for (const char* table : {"campaigns", "sails", "trim_steps", "scans", "analyses", "sections"})
    EXPECT_EQ(scalar(admin, std::string("SELECT count(*) FROM ") + table), 0) << table;
}

TEST_F(PostgreSQLStore, AnUnreachableServerIsOneClearError) {
  const int port = test::PgCluster::shared().port();
  try {
    Database db("postgresql://postgres@127.0.0.1:" + std::to_string(port) + "/no_such_db");
    ADD_FAILURE() << "connected to a database that does not exist";
  } catch (const DatabaseError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find("cannot connect"), std::string::npos) << what;
    EXPECT_NE(what.find("no_such_db"), std::string::npos) << what;
  }
  // A password in the URL never reaches a message.
  try {
    Database db("postgresql://postgres:secret@127.0.0.1:" + std::to_string(port) + "/no_such_db");
  } catch (const DatabaseError& e) {
    EXPECT_EQ(std::string(e.what()).find("secret"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sailshape
