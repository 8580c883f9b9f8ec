#pragma once
// A private PostgreSQL cluster for the tests: initdb and pg_ctl (as the
// `postgres` user when run as root, since PostgreSQL refuses root) in a
// temporary folder, listening on 127.0.0.1 only on a free port, stopped and
// removed when the test process ends. One per test process, started on first
// use; each test takes a fresh database in it.
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
#include <stdexcept>
#include <string>
#include <vector>

#include "database/store.hpp"

namespace sailshape::test {

class PgCluster {
 public:
  // Throws std::runtime_error (one line) when no cluster can be started.
  PgCluster() {
    bin_ = findBin();
    as_root_ = geteuid() == 0;
    stopOrphans();
    std::string pattern = (std::filesystem::temp_directory_path() / "sailshape-pg-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("PostgreSQL test cluster: mkdtemp failed");
    dir_ = pattern;
    std::ofstream(dir_ + "/owner") << getpid();
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
            " -c fsync=off -c synchronous_commit=off -c full_page_writes=off -c max_connections=60\" start > " + dir_ +
            "/pg_ctl.log 2>&1",
        "pg_ctl start", log);
    started_ = true;
  }
  ~PgCluster() {
    if (started_)
      (void)std::system(wrap(bin_ + "/pg_ctl -D " + dir_ + "/data -m immediate -w stop > /dev/null 2>&1").c_str());
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
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
    const std::string name = "sailshape_" + std::to_string(getpid()) + "_" + std::to_string(++counter);
    Database admin(url("postgres"));
    admin.exec("CREATE DATABASE " + name);
    return url(name);
  }

  // The cluster of this test process.
  static PgCluster& shared() {
    static std::unique_ptr<PgCluster> cluster;
    static std::string failure;
    if (!cluster && failure.empty()) {
      try {
        cluster = std::make_unique<PgCluster>();
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    if (!cluster) throw std::runtime_error(failure);
    return *cluster;
  }

 private:
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
        (void)std::system(wrap(bin_ + "/pg_ctl -D " + dir + "/data -m immediate -w stop > /dev/null 2>&1").c_str());
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
};

}  // namespace sailshape::test
