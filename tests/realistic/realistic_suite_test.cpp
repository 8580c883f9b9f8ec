// The realistic one-unit scan suite (issue 34, item 7): a fresh set of configurations each run
// (every sail kind three times, the unit places in turn), each analysed as sailshape's own scan and
// as plain XYZ; fails on any confidently wrong value (|error| > 3σ + target, see realistic_judge.hpp).
// The seed is printed; SAILSHAPE_REALISTIC_SEED replays a run, SAILSHAPE_REALISTIC_COUNT changes
// how many configurations it draws (24), SAILSHAPE_REALISTIC_JSON names a folder for each
// configuration's JSON (config, truth, results, verdicts).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>

#include "tests/support/realistic_judge.hpp"

namespace sailshape::realistic {
namespace {

TEST(RealisticSuite, NoConfidentlyWrongValue) {
  uint64_t base = std::random_device{}() | (static_cast<uint64_t>(std::random_device{}()) << 32);
  if (const char* s = std::getenv("SAILSHAPE_REALISTIC_SEED")) base = std::strtoull(s, nullptr, 10);
  size_t count = 24;
  if (const char* s = std::getenv("SAILSHAPE_REALISTIC_COUNT")) count = std::strtoul(s, nullptr, 10);
  const char* json_dir = std::getenv("SAILSHAPE_REALISTIC_JSON");
  std::printf("SAILSHAPE_REALISTIC_SEED=%llu (replays this run)\n", static_cast<unsigned long long>(base));
  std::mt19937_64 rng(base);
  RunOptions options;
  options.threads = 2;
  size_t within = 0, refused = 0, honest = 0, wrong = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint64_t seed = rng() >> 1;
    const SailKind kind = kSailKinds[i % std::size(kSailKinds)];
    const UnitPlace place = kUnitPlaces[(base + 3 * i) % std::size(kUnitPlaces)];
    const ConfigRun run = runConfig(drawConfig(seed, kind, place), options);
    within += run.count(Verdict::Within);
    refused += run.count(Verdict::Refused);
    honest += run.count(Verdict::Honest);
    wrong += run.count(Verdict::Wrong);
    std::printf("[%zu/%zu] %s: within %zu, refused %zu, honest %zu, wrong %zu\n", i + 1, count,
                run.config.summary().c_str(), run.count(Verdict::Within), run.count(Verdict::Refused),
                run.count(Verdict::Honest), run.count(Verdict::Wrong));
    std::fflush(stdout);
    if (json_dir) std::ofstream(std::string(json_dir) + "/realistic_" + std::to_string(seed) + ".json") << runToJson(run) << "\n";
    for (const std::string& w : wrongValues(run)) ADD_FAILURE() << "confidently wrong: " << w;
  }
  std::printf("values: within %zu, refused %zu, honest %zu, confidently wrong %zu\n", within, refused, honest, wrong);
}

}  // namespace
}  // namespace sailshape::realistic
