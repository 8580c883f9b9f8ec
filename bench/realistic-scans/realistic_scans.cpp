// realistic-scans: N realistic one-unit scans with fresh seeds (tests/support/realistic_*),
// each analysed as sailshape's own scan and as plain XYZ, every reported value judged
// against the generator's truth; a markdown table per sail kind and per unit place.
// Usage and options: README.md here, or --help.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/realistic_judge.hpp"

using namespace sailshape;
using namespace sailshape::realistic;

namespace {

struct Options {
  size_t count = 300;
  std::vector<uint64_t> seeds;  // given: these instead of fresh ones
  std::string table = "realistic-scans.md";
  std::string json_dir, ply_dir;
  std::string sail, place;  // given: every configuration of this sail kind / at this unit place
  int threads = 2;
  bool control = false;
};

void usage() {
  std::puts(
      "realistic-scans [N] [--seed S]... [--sail KIND] [--place PLACE] [--table FILE] [--json DIR] [--ply DIR]\n"
      "                [--control] [--threads T]\n"
      "  N          configurations with fresh seeds (default 300)\n"
      "  --seed S   replay seed S instead (repeatable); N is then ignored\n"
      "  --sail K   only sail kind K: pin-head-main, square-top-main, jib, genoa, asym-bow, asym-sprit,\n"
      "             sym-spinnaker, code-zero (the rest still drawn from the seed)\n"
      "  --place P  only unit place P: deck-leeward, deck-windward, stern-pulpit, mast-foot, bow, boom-end, tunnel\n"
      "  --table F  write the markdown table to F (default realistic-scans.md)\n"
      "  --json DIR write DIR/realistic_<seed>.json per configuration: config, truth, results, verdicts\n"
      "  --ply DIR  write DIR/realistic_<seed>_own.ply (angles, viewpoint), _xyz.ply (points only) and\n"
      "             _sail.ply (the points on the sail alone, for analyze --no-segment)\n"
      "  --control  also analyse each design sampled evenly (4 mm noise, the sail alone, as many points as the\n"
      "             scan put on it): variant even-control, the analysis without the one-unit scan's effects\n"
      "  --threads  threads for each sweep's ray casting (default 2)\n"
      "Example: realistic-scans 40 --json /tmp/rs --table /tmp/rs/table.md");
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "realistic-scans: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      usage();
      std::exit(0);
    } else if (a == "--seed") {
      o.seeds.push_back(std::stoull(next()));
    } else if (a == "--control") {
      o.control = true;
    } else if (a == "--sail") {
      o.sail = next();
    } else if (a == "--place") {
      o.place = next();
    } else if (a == "--table") {
      o.table = next();
    } else if (a == "--json") {
      o.json_dir = next();
    } else if (a == "--ply") {
      o.ply_dir = next();
    } else if (a == "--threads") {
      o.threads = std::stoi(next());
    } else if (!a.empty() && a[0] != '-') {
      o.count = std::stoul(a);
    } else {
      std::fprintf(stderr, "realistic-scans: unknown option %s (see --help)\n", a.c_str());
      std::exit(2);
    }
  }
  return o;
}

// Counts and |error|/σ ratios of the values in one row of the table.
struct Tally {
  size_t runs = 0, within = 0, refused = 0, honest = 0, wrong = 0, analyses_refused = 0;
  std::vector<double> z;  // |error| / σ of every value reported (σ > 0)
  void add(const VariantResult& r) {
    analyses_refused += r.refused;
    for (const JudgedValue& v : r.values) {
      within += v.verdict == Verdict::Within;
      refused += v.verdict == Verdict::Refused;
      honest += v.verdict == Verdict::Honest;
      wrong += v.verdict == Verdict::Wrong;
      if (v.verdict != Verdict::Refused && v.sigma > 0) z.push_back(std::isfinite(v.error) ? v.error / v.sigma : INFINITY);
    }
  }
  double quantile(double q) const {
    if (z.empty()) return NAN;
    std::vector<double> s = z;
    std::sort(s.begin(), s.end());
    return s[std::min(s.size() - 1, static_cast<size_t>(q * static_cast<double>(s.size() - 1) + 0.5))];
  }
};

// One line per configuration with confidently wrong values: which, by how much, against what σ.
std::string wrongLine(const ConfigRun& run) {
  std::string out;
  for (const VariantResult& r : run.variants) {
    std::string values;
    for (const JudgedValue& v : r.values) {
      if (v.verdict != Verdict::Wrong) continue;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s off by %.3g (σ %.2g)", values.empty() ? "" : ", ", v.name.c_str(), v.error,
                    v.sigma);
      values += buf;
    }
    if (!values.empty()) out += (out.empty() ? "" : "; ") + r.variant + ": " + values;
  }
  if (out.empty()) return out;
  return run.config.summary() + " — " + out;
}

std::string row(const std::string& name, const Tally& t) {
  char buf[256];
  const size_t n = t.within + t.refused + t.honest + t.wrong;
  std::snprintf(buf, sizeof buf, "| %s | %zu | %zu | %zu (%.0f %%) | %zu | %zu | %zu | %.2g | %.2g | %.2g |\n", name.c_str(),
                t.runs, n, t.within, n ? 100.0 * t.within / n : 0.0, t.refused, t.honest, t.wrong, t.quantile(0.5),
                t.quantile(0.9), t.quantile(0.99));
  return buf;
}

std::string table(const std::map<std::string, Tally>& rows, const char* by) {
  std::string s = std::string("| ") + by +
                  " | analyses | values | within target | refused / not measured | honest (≤ 3σ + target) | "
                  "confidently wrong | \\|err\\|/σ 50 % | 90 % | 99 % |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [name, t] : rows) s += row(name, t);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  std::vector<uint64_t> seeds = o.seeds;
  if (seeds.empty()) {
    std::random_device rd;
    std::mt19937_64 mix((static_cast<uint64_t>(rd()) << 32) ^ rd() ^
                        static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
    for (size_t i = 0; i < o.count; ++i) seeds.push_back(mix() >> 1);
  }
  RunOptions ro;
  ro.threads = o.threads;
  ro.ply_dir = o.ply_dir;
  ro.even_control = o.control;
  std::map<std::string, Tally> by_sail, by_place, by_variant;
  Tally all;
  std::vector<std::string> wrong;
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < seeds.size(); ++i) {
    ConfigRun run;
    try {
      Config c = drawConfig(seeds[i]);
      if (!o.sail.empty() || !o.place.empty()) {
        const SailKind kind = o.sail.empty() ? c.sail : parseSailKind(o.sail);
        const UnitPlace place = o.place.empty() ? c.place : parseUnitPlace(o.place);
        c = drawConfig(seeds[i], kind, place);
      }
      run = runConfig(c, ro);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "seed %llu: %s\n", static_cast<unsigned long long>(seeds[i]), e.what());
      wrong.push_back("seed " + std::to_string(seeds[i]) + ": the harness failed: " + e.what());
      continue;
    }
    for (const VariantResult& r : run.variants) {
      ++by_variant[r.variant].runs;
      by_variant[r.variant].add(r);
      if (r.variant == "even-control") continue;  // the scans' tables count the scans alone
      for (Tally* t : {&by_sail[sailKindName(run.config.sail)], &by_place[unitPlaceName(run.config.place)], &all}) {
        ++t->runs;
        t->add(r);
      }
    }
    const std::string line = wrongLine(run);
    if (!line.empty()) wrong.push_back(line);
    if (!o.json_dir.empty()) {
      std::ofstream(o.json_dir + "/realistic_" + std::to_string(seeds[i]) + ".json") << runToJson(run) << "\n";
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[%zu/%zu] %s: %zu points (%zu on the sail), within %zu, refused %zu, honest %zu, wrong %zu  (%.0f s)\n",
                i + 1, seeds.size(), run.config.summary().c_str(), run.scan_points, run.sail_hits,
                run.count(Verdict::Within), run.count(Verdict::Refused), run.count(Verdict::Honest),
                run.count(Verdict::Wrong), elapsed);
    std::fflush(stdout);
  }
  std::ostringstream md;
  md << "Realistic one-unit scans: " << seeds.size()
     << " configurations, each analysed as sailshape's own scan and as plain XYZ (targets: camber 0.3 % chord, "
        "draft 2 %, twist 0.3°, entry/exit 2.5°, corners 5 cm, edge lengths 10 cm; wrong = |error| > 3σ + target).\n\n";
  md << table(by_variant, "variant") << "\n" << table(by_sail, "sail") << "\n" << table(by_place, "unit place") << "\n";
  md << table({{"all", all}}, "total (own-scan and plain-xyz)") << "\n";
  md << "Configurations with confidently wrong values (" << wrong.size() << " of " << seeds.size()
     << "; corners and lengths in metres, angles in degrees, camber and draft in %):\n\n";
  for (const std::string& w : wrong) md << "- " << w << "\n";
  std::ofstream(o.table) << md.str();
  std::printf("\n%s", md.str().c_str());
  return 0;
}
