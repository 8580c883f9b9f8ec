#pragma once
// A private PostgreSQL cluster for the tests: initdb and pg_ctl (as the
// `postgres` user when run as root, since PostgreSQL refuses root) in a
// temporary folder, listening on 127.0.0.1 only on a free port, stopped and
// removed at the end; each test takes a fresh database in it. Under ctest one
// cluster serves the whole run (the pg_test_cluster fixture starts it in
// SAILSHAPE_TEST_PG_DIR and stops it after the last test); a test binary run
// by hand starts its own on first use and stops it when it exits.
#include <arpa/inet.h>
#include <glob.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <signal.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "database/store.hpp"

namespace sailshape::test {

class PgCluster {
 public:
  // Starts a cluster in a new temporary folder, or in `dir` (created; then it
  // is left running, its port and programs written there for attach() and
  // stop()). Throws std::runtime_error (one line) when none can be started.
  explicit PgCluster(const std::string& dir = "") {
    bin_ = findBin();
    as_root_ = geteuid() == 0;
    if (dir.empty()) {
      stopOrphans();
      std::string pattern = (std::filesystem::temp_directory_path() / "sailshape-pg-XXXXXX").string();
      if (!mkdtemp(pattern.data())) throw std::runtime_error("PostgreSQL test cluster: mkdtemp failed");
      dir_ = pattern;
      std::ofstream(dir_ + "/owner") << getpid();
    } else {
      dir_ = dir;
      std::filesystem::create_directories(dir_);
      owned_ = false;
    }
    if (as_root_) {
      const passwd* pw = getpwnam("postgres");
      if (!pw) throw std::runtime_error("PostgreSQL test cluster: no `postgres` user to run it as (run scripts/setup)");
      if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0)
        throw std::runtime_error("PostgreSQL test cluster: cannot hand " + dir_ + " to the postgres user");
    }
    port_ = freePort();
    const std::string data = dir_ + "/data", log = dir_ + "/log";
    run(bin_ + "/initdb -D " + data + " -U postgres -A trust --no-locale -E UTF8 --no-sync > " + dir_ + "/initdb.log 2>&1",
        "initdb", dir_ + "/initdb.log");
    // fsync off: the tests kill clients, never the server; durability across a
    // power cut is PostgreSQL's, not ours to test.
    run(bin_ + "/pg_ctl -D " + data + " -l " + log + " -w -t 60 -o \"-p " + std::to_string(port_) +
            " -c listen_addresses=127.0.0.1 -c unix_socket_directories=" + dir_ +
            " -c fsync=off -c synchronous_commit=off -c full_page_writes=off -c max_connections=200\" start > " + dir_ +
            "/pg_ctl.log 2>&1",
        "pg_ctl start", log);
    started_ = true;
    std::ofstream(dir_ + "/bin") << bin_;
    std::ofstream(dir_ + "/port") << port_;
  }
  ~PgCluster() {
    if (!owned_) return;
    if (started_) stop(dir_, bin_, as_root_);
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  // The cluster a PgCluster(dir) left running.
  static std::unique_ptr<PgCluster> attach(const std::string& dir) {
    std::unique_ptr<PgCluster> c(new PgCluster(Attached{}));
    c->dir_ = dir;
    std::ifstream(dir + "/bin") >> c->bin_;
    std::ifstream(dir + "/port") >> c->port_;
    if (c->port_ <= 0) throw std::runtime_error("PostgreSQL test cluster: " + dir + " holds no running cluster");
    return c;
  }
  static void stop(const std::string& dir, const std::string& bin, bool as_root) {
    const std::string command = bin + "/pg_ctl -D " + dir + "/data -m immediate -w stop > /dev/null 2>&1";
    (void)std::system((as_root ? "runuser -u postgres -- sh -c '" + command + "'" : command).c_str());
  }
  PgCluster(const PgCluster&) = delete;
  PgCluster& operator=(const PgCluster&) = delete;

  int port() const { return port_; }
  std::string url(const std::string& database) const {
    return "postgresql://postgres@127.0.0.1:" + std::to_string(port_) + "/" + database;
  }
  // A new, empty database; returns its URL.
  std::string createDatabase() {
    static std::atomic<int> counter{0};
    static const unsigned salt = std::random_device{}();  // a pid can come again within one ctest run
    const std::string name = "sailshape_" + std::to_string(getpid()) + "_" + std::to_string(salt % 100000) + "_" +
                             std::to_string(++counter);
    Database admin(url("postgres"));
    admin.exec("CREATE DATABASE " + name);
    return url(name);
  }

  // The cluster of this test process: ctest's (SAILSHAPE_TEST_PG_DIR) or its own.
  static PgCluster& shared() {
    static std::unique_ptr<PgCluster> cluster;
    static std::string failure;
    if (!cluster && failure.empty()) {
      try {
        const char* dir = std::getenv("SAILSHAPE_TEST_PG_DIR");
        if (dir && *dir) {
          std::ifstream error(std::string(dir) + "/error");
          if (error && std::getline(error, failure)) throw std::runtime_error(failure);
          cluster = attach(dir);
        } else {
          cluster = std::make_unique<PgCluster>();
        }
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    if (!cluster) throw std::runtime_error(failure);
    return *cluster;
  }

 private:
  struct Attached {};
  explicit PgCluster(Attached) : owned_(false) {}

  static std::string findBin() {
    glob_t g{};
    std::string best;
    if (glob("/usr/lib/postgresql/*/bin/initdb", 0, nullptr, &g) == 0)
      for (size_t i = 0; i < g.gl_pathc; ++i) {
        const std::string p = std::filesystem::path(g.gl_pathv[i]).parent_path().string();
        if (best.empty() || std::stoi(std::filesystem::path(p).parent_path().filename().string()) >
                                std::stoi(std::filesystem::path(best).parent_path().filename().string()))
          best = p;
      }
    globfree(&g);
    if (best.empty())
      throw std::runtime_error(
          "PostgreSQL tests need a server: no initdb under /usr/lib/postgresql/*/bin (run scripts/setup)");
    return best;
  }

  // Clusters whose test process died without stopping them (killed by a
  // timeout, say): stopped and removed.
  void stopOrphans() const {
    glob_t g{};
    const std::string pattern = (std::filesystem::temp_directory_path() / "sailshape-pg-*").string();
    if (glob(pattern.c_str(), 0, nullptr, &g) == 0)
      for (size_t i = 0; i < g.gl_pathc; ++i) {
        const std::string dir = g.gl_pathv[i];
        pid_t owner = 0;
        std::ifstream(dir + "/owner") >> owner;
        if (owner <= 0 || kill(owner, 0) == 0 || errno != ESRCH) continue;
        stop(dir, bin_, as_root_);
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
      }
    globfree(&g);
  }

  static int freePort() {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
      if (fd >= 0) close(fd);
      throw std::runtime_error("PostgreSQL test cluster: no free port on 127.0.0.1");
    }
    const int port = ntohs(a.sin_port);
    close(fd);
    return port;
  }

  std::string wrap(const std::string& command) const {
    return as_root_ ? "runuser -u postgres -- sh -c '" + command + "'" : command;
  }

  void run(const std::string& command, const char* what, const std::string& log) const {
    if (std::system(wrap(command).c_str()) != 0) {
      std::ifstream in(log);
      std::string line, last;
      while (std::getline(in, line))
        if (!line.empty()) last = line;
      throw std::runtime_error(std::string("PostgreSQL test cluster: ") + what + " failed: " + last);
    }
  }

  std::string bin_, dir_;
  int port_ = 0;
  bool as_root_ = false;
  bool started_ = false;
  bool owned_ = true;  // stopped and removed by the destructor
};

}  // namespace sailshape::test
