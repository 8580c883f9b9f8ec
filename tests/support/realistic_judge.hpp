#pragma once
// Analyses a realistic one-unit scan (realistic_scene.hpp, realistic_sweep.hpp) the
// way `sailshape analyze` does (analyzeSail on the whole scene cloud: it segments
// first), twice: as sailshape's own scan (scan angles, RSSI, viewpoint) and as plain
// XYZ (points only). Every value it reports is judged against the generator's truth:
//   within    |error| ≤ target (issue 34: camber 0.3 % chord, draft 2 %, twist 0.3°,
//             entry/exit 2.5°, corners 5 cm; edge lengths 10 cm, two corners' worth);
//   refused   the analysis threw AnalysisError, or listed the section as not measured;
//   honest    target < |error| ≤ 3σ + target, σ the value's own reported 1σ;
//   wrong     |error| > 3σ + target: a confidently wrong value (or a NaN).
// Sections are matched to the truth by their fraction, as the pipeline's own accuracy
// tests do: SailSurface::section(s.fraction).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/pipeline/pipeline.hpp"
#include "tests/support/realistic_scene.hpp"
#include "tests/support/realistic_sweep.hpp"

namespace sailshape::realistic {

enum class Verdict { Within, Refused, Honest, Wrong };
std::string verdictName(Verdict v);  // "within", "refused", "honest", "wrong"

// The verdict on a reported value with |error| `error`, its reported 1σ `sigma`, against `target`.
Verdict verdictFor(double error, double sigma, double target);

struct Targets {
  double camber_pct = 0.3, draft_pct = 2.0, twist_deg = 0.3, end_deg = 2.5, corner_m = 0.05, length_m = 0.10;
};

struct JudgedValue {
  std::string name;          // "camber_pct@0.50", "tack_m", "luff_length_m", ...
  Verdict verdict = Verdict::Refused;
  double measured = 0, sigma = 0, truth = 0;  // for corners: measured = truth = 0, error = distance
  bool is_corner = false;
  Vec3 measured_point = Vec3::Zero(), truth_point = Vec3::Zero();  // a corner's, boat frame, m
  double error = 0;          // |measured − truth| (corner: distance), same units
  double target = 0;
  std::string reason;        // why refused / not measured
};

struct VariantResult {
  std::string variant;       // "own-scan", "plain-xyz" (or "even-control")
  bool refused = false;      // analyzeSail threw
  std::string refusal;       // its one line
  double seconds = 0;
  size_t sail_points = 0;    // what the analysis kept as sail
  std::vector<JudgedValue> values;
  size_t count(Verdict v) const;
};

struct ConfigRun {
  Config config;
  Truth truth;
  size_t scan_points = 0, sail_hits = 0;  // all points; points on the sail
  std::array<size_t, 5> sail_beams{};
  double scan_seconds = 0;
  std::vector<VariantResult> variants;    // own-scan, plain-xyz
  size_t count(Verdict v) const;
};

struct RunOptions {
  int threads = 1;            // for the sweep
  // Non-empty: write <dir>/realistic_<seed>_own.ply (angles, RSSI, viewpoint), _xyz.ply (points only)
  // and _sail.ply (the own scan's points on the sail alone).
  std::string ply_dir;
  Targets targets;
  // Also analyse the same design sampled evenly (sampleSail: as many points as the scan put on the
  // sail, 4 mm noise along the rays, the sail alone): variant "even-control", what the analysis gives
  // on these sails without the one-unit scan's density changes and gaps.
  bool even_control = false;
};

// Every value `a` reports judged against `truth` (the flying sail `design`'s), into out.values;
// with `a` null, every value refused for `refusal`.
void judgeAnalysis(const SailAnalysis* a, const std::string& refusal, const Truth& truth, const SailDesign& design,
                   const Targets& targets, VariantResult& out);

// Draws the configuration from `seed`, sweeps it and judges both analyses.
ConfigRun runSeed(uint64_t seed, const RunOptions& options = {});
ConfigRun runConfig(const Config& config, const RunOptions& options = {});

// Seed, config, truth, both results and every value's verdict, as JSON text (for replaying a case).
std::string runToJson(const ConfigRun& run);
// One line per confidently wrong value: "seed 12 (genoa at bow, plain-xyz): head_m 0.412 m off, σ 0.021".
std::vector<std::string> wrongValues(const ConfigRun& run);

}  // namespace sailshape::realistic
