// ctest's fixture around the PostgreSQL tests: `start DIR` starts one private
// cluster (pg_cluster.hpp) for the whole run, `stop DIR` stops and removes it.
// A cluster that cannot start is not this step's failure: the reason is left
// in DIR/error and every PostgreSQL test fails with it, while the SQLite ones run.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "pg_cluster.hpp"

int main(int argc, char** argv) {
  const std::string usage = "usage: pg_test_cluster start|stop DIR";
  if (argc != 3) {
    std::fprintf(stderr, "%s\n", usage.c_str());
    return 2;
  }
  const std::string command = argv[1], dir = argv[2];
  std::error_code ec;
  if (command == "start") {
    std::filesystem::remove_all(dir, ec);
    try {
      sailshape::test::PgCluster cluster(dir);
      std::printf("PostgreSQL test cluster on 127.0.0.1:%d in %s\n", cluster.port(), dir.c_str());
    } catch (const std::exception& e) {
      std::filesystem::create_directories(dir, ec);
      std::ofstream(dir + "/error") << e.what() << "\n";
      std::printf("%s\n", e.what());
    }
    return 0;
  }
  if (command == "stop") {
    std::string bin;
    std::ifstream(dir + "/bin") >> bin;
    if (!bin.empty()) sailshape::test::PgCluster::stop(dir, bin, geteuid() == 0);
    std::filesystem::remove_all(dir, ec);
    return 0;
  }
  std::fprintf(stderr, "%s\n", usage.c_str());
  return 2;
}
