// `sailshape scan`: sweep one or more scanner units and store their clouds, raw samples and telegrams.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "acquisition/sweep.hpp"
#include "acquisition/sweep_io.hpp"
#include "acquisition/sync.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "cli/commands.hpp"
#include "cli/json_file.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

namespace fs = std::filesystem;

struct ScanOptions {
  std::vector<std::string> units;
  std::string out;
  bool trigger = false;
  bool no_home = false;
  bool quiet = false;
  double home_timeout_s = SweepOptions{}.home_timeout_s;
  double ready_timeout_s = SweepOptions{}.ready_timeout_s;
  double sync_timeout_s = SyncOptions{}.ready_timeout_s;
};

std::string fileBase(const UnitConfig& u) {
  std::string s = u.name;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return s.empty() ? "unit" : s;
}

void run(const ScanOptions& o) {
  std::vector<UnitConfig> units;
  for (const std::string& path : o.units) units.push_back(readUnitFile(path));
  std::vector<std::string> bases;
  for (const UnitConfig& u : units) {
    const std::string b = fileBase(u);
    if (std::find(bases.begin(), bases.end(), b) != bases.end())
      throw InvalidInput("[scan] two units are named '" + u.name + "'; unit names must differ");
    bases.push_back(b);
  }
  SweepOptions so;
  so.home = !o.no_home;
  so.home_timeout_s = o.home_timeout_s;
  so.ready_timeout_s = o.ready_timeout_s;
  // Bad waits are refused before anything is written.
  validateSweepOptions(so);
  if (!(o.sync_timeout_s > 0))
    throw InvalidInput("[scan] --sync-timeout must be > 0 (got " + formatFixed(o.sync_timeout_s, 3) + ")");
  fs::create_directories(o.out);
  // Never overwrite a stored scan.
  for (const std::string& b : bases)
    for (const char* ext : {".ply", ".samples.csv", ".sscap"})
      if (fs::exists(fs::path(o.out) / (b + ext)))
        throw FileError("[scan] " + (fs::path(o.out) / (b + ext)).string() + " exists already; choose another --out");
  if (fs::exists(fs::path(o.out) / "scan.json"))
    throw FileError("[scan] " + (fs::path(o.out) / "scan.json").string() + " exists already; choose another --out");

  std::vector<Sweep> sweeps(units.size());
  std::vector<std::string> errors(units.size());
  double spread = 0;
  ProgressBar bar(!o.quiet);
  if (o.trigger) {
    SyncOptions sync;
    sync.sweep = so;
    sync.ready_timeout_s = o.sync_timeout_s;
    for (const std::string& b : bases) sync.capture_paths.push_back((fs::path(o.out) / (b + ".sscap")).string());
    const SynchronisedSweeps r = runSynchronisedSweeps(units, sync, bar.progress());
    sweeps = r.sweeps;
    errors = r.errors;
    spread = r.start_spread_s;
  } else {
    for (size_t i = 0; i < units.size(); ++i) {
      SweepOptions uo = so;
      uo.capture_path = (fs::path(o.out) / (bases[i] + ".sscap")).string();
      try {
        sweeps[i] = runSweep(units[i], uo, bar.progress());
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    }
  }
  bar.finish();

  nlohmann::json doc{{"units", nlohmann::json::array()}, {"trigger", o.trigger}};
  if (o.trigger) doc["start_spread_s"] = spread;
  std::vector<std::string> problems;
  for (size_t i = 0; i < units.size(); ++i) {
    const Sweep& s = sweeps[i];
    nlohmann::json u{{"name", units[i].name}, {"unit_file", o.units[i]}};
    if (!errors[i].empty()) {
      u["error"] = errors[i];
      problems.push_back(units[i].name + ": " + errors[i]);
    } else {
      const fs::path cloud = fs::path(o.out) / (bases[i] + ".ply");
      const fs::path samples = fs::path(o.out) / (bases[i] + ".samples.csv");
      writeCloud(cloud.string(), s.cloud);
      writeSweepSamples(samples.string(), s.points);
      u.update({{"cloud", cloud.filename().string()},
                {"samples", samples.filename().string()},
                {"points", s.points.size()},
                {"scans", s.scans},
                {"scans_missed", s.scans_missed},
                {"partial", s.partial},
                {"beta_start_deg", s.beta_start_deg},
                {"beta_end_deg", s.beta_end_deg},
                {"trigger_time_s", s.trigger_time_s},
                {"start_time_s", s.start_time_s},
                {"warnings", s.warnings}});
      if (fs::exists(fs::path(o.out) / (bases[i] + ".sscap"))) u["capture"] = bases[i] + ".sscap";
      if (s.partial) {
        u["message"] = s.message;
        problems.push_back(units[i].name + ": partial sweep (" + s.message + "), " + std::to_string(s.points.size()) +
                           " points kept");
      }
      std::printf("%s: %zu points from %zu scans, beta %.2f..%.2f deg%s\n", units[i].name.c_str(), s.points.size(),
                  s.scans, s.beta_start_deg, s.beta_end_deg, s.partial ? " (PARTIAL)" : "");
      for (const std::string& w : s.warnings) std::fprintf(stderr, "warning: %s: %s\n", units[i].name.c_str(), w.c_str());
    }
    doc["units"].push_back(u);
  }
  if (o.trigger) std::printf("start-time spread over the units: %.1f ms\n", spread * 1000);
  writeJsonFile((fs::path(o.out) / "scan.json").string(), doc);
  if (!problems.empty()) {
    std::string all;
    for (const std::string& p : problems) all += (all.empty() ? "" : "; ") + p;
    throw AnalysisError("[scan] " + all + " (what was received is in " + o.out + ")");
  }
}

}  // namespace

void addScanCommand(CLI::App& app) {
  auto o = std::make_shared<ScanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "scan",
      "Sweep scanner units and write their clouds, samples and raw captures\n\n"
      "Sweep scanner units: home each turntable, move to the start angle, stream scans while rotating through the "
      "sweep angle, stop. Writes per unit NAME.ply (cloud by SPEC §2 with the unit's p, θ and pose), "
      "NAME.samples.csv (r, α, β, RSSI, time per point), NAME.sscap (raw telegrams, for `sailshape replay`) and "
      "scan.json. A sweep cut short keeps its points and fails the command after writing them.");
  cmd->add_option("--unit", o->units, "Unit file (UNIT.json); repeat for several units")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "Output directory (created; existing scan files in it are never overwritten)")
      ->required();
  cmd->add_flag("--trigger", o->trigger,
                "Start all units together: once every unit is homed and streaming, a UDP trigger on loopback starts "
                "their sweeps; the spread of start times is reported");
  cmd->add_flag("--no-home", o->no_home, "Skip homing (the turntable was homed since power-on)");
  cmd->add_option("--home-timeout", o->home_timeout_s, "Longest wait for a turntable to find its home sensor, seconds")
      ->capture_default_str();
  cmd->add_option("--ready-timeout", o->ready_timeout_s,
                  "Longest wait, once a scanner is set up, for its first streamed scan (a unit just powered on "
                  "answers busy and streams nothing while it spins up), seconds")
      ->capture_default_str();
  cmd->add_option("--sync-timeout", o->sync_timeout_s,
                  "With --trigger: longest wait for every unit to be homed and streaming before the trigger, seconds")
      ->capture_default_str();
  cmd->add_flag("--quiet", o->quiet, "No progress bar");
  cmd->callback([o] { run(*o); });
}

}  // namespace sailshape::cli
