// sailshape-db-bench: the store's import and query times on both backends, on
// the same 1,000 scans (4 sails on 2 boats, 2 campaigns, 25 tests of 10 trim
// steps; 20 sections per scan with a 3-point curve; a 10,000-point cloud per
// scan; fixed seed 11). SQLite in a temporary file; PostgreSQL on the server
// SAILSHAPE_BENCH_PG names (an empty database) or, without it, on a private
// cluster started as the tests start theirs (fsync off there: the times are
// the client's and the server's work, not the disk's).
#include <chrono>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/schema.hpp"
#include "tests/database/pg_cluster.hpp"

namespace {

using namespace sailshape;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Imports the 1,000 scans, one transaction each; returns seconds.
double fill(Database& db, int scans) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> awa(30, 170), force(50, 500), control(0, 1), camber(5, 20), u(-1, 1);
  nlohmann::json doc;
  doc["sections"] = nlohmann::json::array();
  for (int k = 0; k < 20; ++k) doc["sections"].push_back({{"fraction", (k + 1) / 21.0}});
  Cloud cloud;
  for (int i = 0; i < 10'000; ++i) cloud.points.emplace_back(u(rng), u(rng), u(rng));
  const auto t0 = Clock::now();
  for (int scan = 0; scan < scans; ++scan) {
    const int sail = scan / 250, test = (scan % 250) / 10, step = scan % 10;
    ImportMetadata m;
    m.campaign = "campaign-" + std::to_string(sail % 2);
    m.boat = "boat-" + std::to_string(sail % 2);
    m.sail = "sail-" + std::to_string(sail);
    m.sail_type = sail % 2 ? "genoa" : "mainsail";
    m.test = "test-" + std::to_string(test);
    m.trim_step = step;
    m.awa_deg = awa(rng);
    m.drive_n = force(rng);
    m.side_n = force(rng);
    m.controls = {{"sheet", control(rng)}, {"tack_height", control(rng)}};
    for (auto& sec : doc["sections"]) {
      sec["camber_pct"] = camber(rng);
      sec["draft_pct"] = 40.0;
      sec["twist_deg"] = 10.0;
      sec["uncertainty"] = {{"camber_pct", 0.2}};
      sec["curve"] = {{0.0, 0.0, 1.0}, {1.0, 0.1, 1.0}, {2.0, 0.0, 1.0}};
    }
    importScan(db, m, &doc, &cloud);
  }
  return secondsSince(t0);
}

struct Query {
  const char* what;
  std::function<Table(Database&)> run;
};

std::vector<Query> queries() {
  ScanFilter one_sail;
  one_sail.sail = "sail-1";
  one_sail.awa_min_deg = 90;
  one_sail.awa_max_deg = 100;
  ScanFilter type_control;
  type_control.sail_type = "genoa";
  type_control.control = "sheet";
  type_control.control_min = 0.4;
  type_control.control_max = 0.5;
  ScanFilter campaign;
  campaign.campaign = "campaign-0";
  ScanFilter awa;
  awa.awa_min_deg = 94;
  awa.awa_max_deg = 96;
  return {
      {"scans of one sail, AWA 90-100", [=](Database& db) { return findScans(db, one_sail); }},
      {"scans of one sail type, sheet 0.4-0.5", [=](Database& db) { return findScans(db, type_control); }},
      {"all scans of one campaign", [=](Database& db) { return findScans(db, campaign); }},
      {"sections of all scans at AWA 94-96", [=](Database& db) { return findSections(db, awa); }},
      {"camber evolution over one test", [](Database& db) { return parameterEvolution(db, "test-3", "camber_pct", 0.5); }},
      {"two sails side by side at 95 +- 5", [](Database& db) { return compareSails(db, "sail-1", "sail-3", 95.0, 5.0); }},
      {"5 best trim steps by drive/side, AWA 85-105",
       [](Database& db) { return bestTrimSteps(db, 85, 105, TrimCriterion::DriveOverSide, 5); }},
  };
}

// Median milliseconds of `repeats` runs, and the rows.
std::pair<double, size_t> time(Database& db, const Query& q, int repeats) {
  std::vector<double> ms;
  size_t rows = 0;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    rows = q.run(db).rows.size();
    ms.push_back(secondsSince(t0) * 1000);
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], rows};
}

}  // namespace

int main(int argc, char** argv) {
  const int scans = argc > 1 ? std::atoi(argv[1]) : 1000;
  const std::string file = "/tmp/sailshape-db-bench-" + std::to_string(getpid()) + ".db";
  std::unique_ptr<test::PgCluster> cluster;
  std::string url;
  if (const char* given = std::getenv("SAILSHAPE_BENCH_PG")) {
    url = given;
  } else {
    cluster = std::make_unique<test::PgCluster>();
    url = cluster->createDatabase();
  }
  Database lite = openSailDatabase(file);
  Database pg = openSailDatabase(url);
  std::printf("importing %d scans (20 sections, a 10,000-point cloud each), one transaction per scan\n", scans);
  const double lite_s = fill(lite, scans);
  const double pg_s = fill(pg, scans);
  std::printf("| | SQLite | PostgreSQL |\n|---|---|---|\n");
  std::printf("| import, %d scans (s) | %.2f | %.2f |\n", scans, lite_s, pg_s);
  std::printf("| import, per scan (ms) | %.1f | %.1f |\n", 1000 * lite_s / scans, 1000 * pg_s / scans);
  for (const Query& q : queries()) {
    const auto [lite_ms, lite_rows] = time(lite, q, 21);
    const auto [pg_ms, pg_rows] = time(pg, q, 21);
    std::printf("| %s: %zu rows (ms) | %.2f | %.2f |%s\n", q.what, lite_rows, lite_ms, pg_ms,
                lite_rows == pg_rows ? "" : " ROWS DIFFER");
  }
  for (const char* tail : {"", "-wal", "-shm"}) std::remove((file + tail).c_str());
  return 0;
}
