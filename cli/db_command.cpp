// `sailshape db`: the design-flying database (database/).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "acquisition/sensor_model.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/params_io.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "cli/commands.hpp"
#include "cli/db_design_command.hpp"
#include "cli/progress_bar.hpp"
#include "cli/sail_design.hpp"
#include "database/catalog.hpp"
#include "database/copy.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "database/table_export.hpp"

namespace sailshape::cli {
namespace {

struct DbOptions {
  std::string db, file, dest;
  bool append = false;
  int busy_timeout_ms = 5000;
  // import
  ImportMetadata meta;
  std::string cloud_file, scanner;
  double awa = NAN, aws = NAN, drive = NAN, side = NAN, heel = NAN;
  std::vector<std::string> sets, pressures;
  // queries
  ScanFilter filter;
  std::string boat, sail, sail_type, campaign, test, control;
  double awa_min = NAN, awa_max = NAN, control_min = NAN, control_max = NAN;
  bool sections = false;
  std::string evolution;
  double fraction = 0.5;
  std::vector<std::string> compare;
  double at_awa = NAN, awa_tolerance = 5.0;
  std::string best;
  int limit = 1;
  bool csv = false, json = false;
  int64_t scan_id = 0;
};

std::optional<double> given(double v) { return std::isnan(v) ? std::nullopt : std::optional<double>(v); }
std::optional<std::string> given(const std::string& s) { return s.empty() ? std::nullopt : std::optional<std::string>(s); }

OpenOptions openOptions(const DbOptions& o, bool create) {
  OpenOptions oo;
  oo.create = create;
  oo.busy_timeout_ms = o.busy_timeout_ms;
  return oo;
}

// Every db command but init works on an existing file; SQLite's own message
// ("unable to open database file") does not say what to do about a missing one.
// A PostgreSQL URL names a database on a server, which says itself when it is missing.
void requireExisting(const DbOptions& o, const char* command) {
  std::error_code ec;
  if (!isPostgresUrl(o.db) && !std::filesystem::exists(o.db, ec))
    throw InvalidInput(std::string("db ") + command + ": " + o.db + " does not exist; run `sailshape db init " + o.db +
                       "` first");
}

// Opens an existing sailshape database (migrating it when older and writable).
Database openExisting(const DbOptions& o, const char* command) {
  requireExisting(o, command);
  return openSailDatabase(o.db, openOptions(o, false));
}

std::map<std::string, double> parseAssignments(const std::vector<std::string>& items, const char* option) {
  std::map<std::string, double> out;
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InvalidInput(std::string("db import: ") + option + " expects NAME=VALUE (got \"" + item + "\")");
    const std::string value = item.substr(eq + 1);
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != value.size())
      throw InvalidInput(std::string("db import: ") + option + " " + item.substr(0, eq) + " needs a number (got \"" + value + "\")");
    out[item.substr(0, eq)] = v;
  }
  return out;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && std::equal(tail.rbegin(), tail.rend(), s.rbegin(),
                                               [](char a, char b) { return std::tolower(a) == b; });
}

std::string text(const Value& v) {
  if (std::holds_alternative<int64_t>(v)) return std::to_string(std::get<int64_t>(v));
  if (std::holds_alternative<double>(v)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", std::get<double>(v));
    return buf;
  }
  if (std::holds_alternative<std::string>(v)) return std::get<std::string>(v);
  return "-";
}

void printTable(const Table& t) {
  std::vector<size_t> width(t.columns.size());
  for (size_t c = 0; c < t.columns.size(); ++c) width[c] = t.columns[c].size();
  for (const auto& row : t.rows)
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], text(row[c]).size());
  for (size_t c = 0; c < t.columns.size(); ++c) std::printf("%-*s%s", int(width[c]), t.columns[c].c_str(), c + 1 < t.columns.size() ? "  " : "\n");
  for (const auto& row : t.rows)
    for (size_t c = 0; c < row.size(); ++c) std::printf("%-*s%s", int(width[c]), text(row[c]).c_str(), c + 1 < row.size() ? "  " : "\n");
  std::printf("(%zu rows)\n", t.rows.size());
}

void emit(const Table& t, const DbOptions& o) {
  if (o.csv) std::cout << tableToCsv(t);
  else if (o.json) std::cout << tableToJson(t).dump(2) << "\n";
  else printTable(t);
}

ScanFilter filterOf(const DbOptions& o) {
  ScanFilter f;
  f.boat = given(o.boat);
  f.sail = given(o.sail);
  f.sail_type = given(o.sail_type);
  f.campaign = given(o.campaign);
  f.test = given(o.test);
  f.control = given(o.control);
  f.awa_min_deg = given(o.awa_min);
  f.awa_max_deg = given(o.awa_max);
  f.control_min = given(o.control_min);
  f.control_max = given(o.control_max);
  return f;
}

Table runQuery(Database& db, const DbOptions& o) {
  const ScanFilter f = filterOf(o);
  if (!o.evolution.empty()) {
    if (o.test.empty()) throw InvalidInput("db query: --evolution needs --test");
    return parameterEvolution(db, o.test, o.evolution, o.fraction, f);
  }
  if (!o.compare.empty()) {
    if (o.compare.size() != 2) throw InvalidInput("db query: --compare needs two sails, SAIL_A,SAIL_B (got " + std::to_string(o.compare.size()) + ")");
    if (std::isnan(o.at_awa)) throw InvalidInput("db query: --compare needs --at-awa");
    return compareSails(db, o.compare[0], o.compare[1], o.at_awa, o.awa_tolerance);
  }
  if (!o.best.empty()) {
    if (std::isnan(o.awa_min) || std::isnan(o.awa_max)) throw InvalidInput("db query: --best needs --awa-min and --awa-max");
    ScanFilter rest = f;
    rest.awa_min_deg.reset();
    rest.awa_max_deg.reset();
    return bestTrimSteps(db, o.awa_min, o.awa_max, o.best == "drive" ? TrimCriterion::Drive : TrimCriterion::DriveOverSide,
                         o.limit, rest);
  }
  return o.sections ? findSections(db, f) : findScans(db, f);
}

// The analysis of `scan` for the sail m.sail's current design (version `version`):
// sets m.region and m.design_comparison. Throws when the sail is not found in it
// (nothing is stored then).
nlohmann::json analyseForDesign(Database& db, const Cloud& scan, int version, const std::string& scanner,
                                ImportMetadata& m) {
  const Mesh design = designVersionMesh(db, m.sail, version);
  AnalysisParams params;
  if (!scanner.empty()) useScannerBeam(params.outline, parseScannerModel(scanner));
  const MeshSections design_sections = designSections(design, params.sections);
  m.region = ScanRegion{designRegion(design, plausibleTrimDeviationM(design)), version};
  SailAnalysis a;
  try {
    ProgressBar bar(true);
    a = analyzeInRegion(scan, m.region->box, design, params, bar.progress());
    bar.finish();
  } catch (const AnalysisError& e) {
    throw AnalysisError("db import: sail \"" + m.sail + "\" (design version " + std::to_string(version) +
                        ") not found in the scan: " + userMessage(e.what()) + "; nothing stored");
  }
  const DesignCheck check = checkAgainstDesign(design, design_sections, a);
  m.design_comparison = ImportMetadata::Comparison{check.comparison.stats,
                                                   {{"sections", sectionDeltasToJson(check.comparison.sections)},
                                                    {"design_version", version},
                                                    {"mismatch", check.mismatch}}};
  nlohmann::json doc = analysisToJson(a);
  doc["parameters"] = paramsToJson(params);
  std::printf("analysed sail \"%s\" in its design's region (%s m): %zu points; deviation from design version %d: "
              "mean %+.1f mm, RMS %.1f mm\n",
              m.sail.c_str(), formatRegionBox(m.region->box).c_str(), a.sail_points, version,
              1000 * check.comparison.stats.mean_m, 1000 * check.comparison.stats.rms_m);
  return doc;
}

void runImport(DbOptions o) {
  Database db = openExisting(o, "import");
  ImportMetadata& m = o.meta;
  m.awa_deg = given(o.awa);
  m.aws_m_s = given(o.aws);
  m.drive_n = given(o.drive);
  m.side_n = given(o.side);
  m.heel_moment_nm = given(o.heel);
  m.controls = parseAssignments(o.sets, "--set");
  m.pressures_pa = parseAssignments(o.pressures, "--pressure");
  if (m.raw_capture.empty()) m.raw_capture = o.file;
  std::optional<nlohmann::json> doc;
  std::optional<Cloud> cloud;
  std::string cloud_path = o.cloud_file;
  if (endsWith(o.file, ".json")) {
    std::ifstream in(o.file);
    if (!in) throw FileError(o.file + ": cannot open");
    try {
      doc = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw FileError(o.file + ": not valid JSON (" + e.what() + ")");
    }
    if (doc->contains("input") && (*doc)["input"].is_string() && m.raw_capture == o.file)
      m.raw_capture = (*doc)["input"].get<std::string>();
    // `analyze --design` analysed its sail within a region: the stored cloud keeps it.
    const nlohmann::json region = doc->value("design", nlohmann::json::object()).value("region_m", nlohmann::json());
    if (region.is_string()) m.region = ScanRegion{parseRegionBox(region.get<std::string>()), 0};
  } else {
    if (!cloud_path.empty()) throw InvalidInput("db import: --cloud applies to an analysis JSON FILE only");
    cloud_path = o.file;
  }
  if (!cloud_path.empty()) {
    CloudReadResult r = readCloud(cloud_path);
    for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s: %s\n", cloud_path.c_str(), w.c_str());
    cloud = std::move(r.cloud);
  }
  // A scan of a sail with a design is analysed as that sail: cropped to its region, the
  // cluster matching the design; the region is stored so every re-analysis does the same.
  const int design_version = doc ? 0 : currentDesignVersion(db, m.sail);
  if (design_version > 0) doc = analyseForDesign(db, *cloud, design_version, o.scanner, m);
  const ImportResult r = importScan(db, m, doc ? &*doc : nullptr, cloud ? &*cloud : nullptr);
  // The step as the user numbered it within its test; the row id is what
  // `db query --best` lists as trim_step_id.
  const std::string test = m.test.empty() ? "" : " of test \"" + m.test + "\"";
  std::printf("imported scan %lld (trim step %d%s, trim step id %lld, %zu sections)\n", static_cast<long long>(r.scan_id),
              m.trim_step, test.c_str(), static_cast<long long>(r.trim_step_id), r.sections);
}

void addFilterOptions(CLI::App* cmd, DbOptions& o) {
  cmd->add_option("--boat", o.boat, "Only scans of this boat");
  cmd->add_option("--sail", o.sail, "Only scans of this sail");
  cmd->add_option("--sail-type", o.sail_type, "Only sails of this type (mainsail, genoa, gennaker, ...)");
  cmd->add_option("--campaign", o.campaign, "Only scans of this campaign");
  cmd->add_option("--test", o.test, "Only trim steps of this test");
  cmd->add_option("--awa-min", o.awa_min, "Lowest apparent wind angle, degrees");
  cmd->add_option("--awa-max", o.awa_max, "Highest apparent wind angle, degrees");
  cmd->add_option("--control", o.control, "Only trim steps with this control setting (tack_height, sheet, ...)");
  cmd->add_option("--control-min", o.control_min, "Lowest value of --control")->needs("--control");
  cmd->add_option("--control-max", o.control_max, "Highest value of --control")->needs("--control");
}

void addQueryOptions(CLI::App* cmd, DbOptions& o) {
  addFilterOptions(cmd, o);
  auto* sections = cmd->add_flag("--sections", o.sections, "One row per section (all parameters and uncertainties) instead of per scan");
  auto* evolution = cmd->add_option("--evolution", o.evolution,
                                    "A parameter's evolution over the trim steps of --test: chord_m, camber_pct, draft_pct, "
                                    "twist_deg, twist_rel_deg, entry_deg or exit_deg")
                        ->check(CLI::IsMember(sectionParameterNames()));
  cmd->add_option("--fraction", o.fraction, "Section height fraction for --evolution (nearest section; default 0.5)");
  auto* compare = cmd->add_option("--compare", o.compare, "Two sails side by side: SAIL_A,SAIL_B (with --at-awa)")->delimiter(',');
  cmd->add_option("--at-awa", o.at_awa, "Apparent wind angle for --compare, degrees");
  cmd->add_option("--awa-tolerance", o.awa_tolerance, "Largest AWA difference accepted by --compare, degrees (default 5)");
  auto* best = cmd->add_option("--best", o.best, "Best trim steps in --awa-min..--awa-max by drive or drive-side (drive/side ratio)")
                   ->check(CLI::IsMember({"drive", "drive-side"}));
  cmd->add_option("--limit", o.limit, "Rows returned by --best (default 1)")->check(CLI::PositiveNumber);
  sections->excludes(evolution)->excludes(compare)->excludes(best);
  evolution->excludes(compare)->excludes(best);
  compare->excludes(best);
}

// `db import`'s options: the file, and the campaign, session, sail, test and conditions it belongs to.
void addImportOptions(CLI::App* imp, DbOptions& o) {
  imp->add_option("FILE", o.file, "Analysis JSON (.json) or cloud (.ply, .pcd, .xyz, .txt, .csv)")->required()->check(CLI::ExistingFile);
  imp->add_option("--cloud", o.cloud_file, "With an analysis JSON FILE: also store this cloud (compressed)")->check(CLI::ExistingFile);
  imp->add_option("--campaign", o.meta.campaign, "Campaign name, created when new (default \"default\")");
  imp->add_option("--campaign-kind", o.meta.campaign_kind, "For a new campaign: full_scale (default) or wind_tunnel")
      ->check(CLI::IsMember({"full_scale", "wind_tunnel"}));
  imp->add_option("--session", o.meta.session, "Session within the campaign (default \"default\")");
  imp->add_option("--boat", o.meta.boat, "Boat carrying the sail");
  imp->add_option("--sail", o.meta.sail, "Sail name, created when new (default \"default\")");
  imp->add_option("--sail-type", o.meta.sail_type, "Sail type: mainsail, genoa, gennaker, spinnaker, ...");
  imp->add_option("--test", o.meta.test, "Test (a series of trim steps) this scan belongs to");
  imp->add_option("--trim-step", o.meta.trim_step, "Order of the trim step within the test (default 0)");
  imp->add_option("--awa", o.awa, "Apparent wind angle, degrees");
  imp->add_option("--aws", o.aws, "Apparent wind speed, m/s");
  imp->add_option("--drive", o.drive, "Measured drive force, N");
  imp->add_option("--side", o.side, "Measured side force, N");
  imp->add_option("--heel", o.heel, "Measured heel moment, N·m");
  imp->add_option("--set", o.sets, "Control setting NAME=VALUE (tack_height, sheet, traveller, halyard, ...); repeatable")->allow_extra_args(false);
  imp->add_option("--pressure", o.pressures, "Pressure tap TAP=PASCAL; repeatable")->allow_extra_args(false);
  imp->add_option("--unit", o.meta.scanner_unit, "Scanner unit serial");
  imp->add_option("--scanner", o.scanner,
                  "A cloud FILE for a sail with a design is analysed as `sailshape analyze --design` does; this names "
                  "the scanner model (lms111 or lms511) for its beam footprint, as `analyze --scanner`")
      ->check(CLI::IsMember({"lms111", "lms511"}, CLI::ignore_case));
  imp->add_option("--scanned-at", o.meta.scanned_at, "Scan time, ISO 8601");
  imp->add_option("--raw-capture", o.meta.raw_capture, "Reference to the raw capture (default: the input file)");
}

// `db show`: one scan, its sections and the sections it could not measure; optionally its stored cloud.
void runShow(const DbOptions& o) {
  Database d = openExisting(o, "show");
  ScanFilter f;
  f.scan_id = o.scan_id;
  const Table scan = findScans(d, f);
  if (scan.rows.empty()) throw InvalidInput("db show: no scan " + std::to_string(o.scan_id) + " in " + o.db);
  if (!o.cloud_file.empty()) {
    const ScanRecord record = loadScanRecord(d, o.scan_id);
    if (!record.cloud)
      throw InvalidInput("db show: scan " + std::to_string(o.scan_id) + " has no stored cloud (only its analysis was imported)");
    // The sail's region when one is stored: what every analysis of the scan analyses.
    // Mixed pixels go first, on the whole scan, as the surfaces behind tell them.
    const Cloud out =
        record.region ? cropToRegion(withoutMixedPixels(*record.cloud, AnalysisParams{}), record.region->box) : *record.cloud;
    writeCloud(o.cloud_file, out);
    if (record.region)
      std::fprintf(stderr, "wrote the stored cloud of scan %lld in its sail's region %s m (%zu of %zu points) to %s\n",
                   static_cast<long long>(o.scan_id), formatRegionBox(record.region->box).c_str(), out.size(),
                   record.cloud->size(), o.cloud_file.c_str());
    else
      std::fprintf(stderr, "wrote the stored cloud of scan %lld (%zu points) to %s\n", static_cast<long long>(o.scan_id),
                   record.cloud->size(), o.cloud_file.c_str());
  }
  const Table sections = findSections(d, f);
  // Sections the latest analysis was asked for but could not measure.
  const int64_t analysis_id = latestAnalysisId(d, o.scan_id);
  const std::vector<UnmeasuredSection> unmeasured =
      analysis_id == 0 ? std::vector<UnmeasuredSection>{} : unmeasuredSections(d, analysis_id);
  if (o.json) {
    nlohmann::ordered_json j = tableToJson(scan)[0];
    j["sections"] = tableToJson(sections);
    j["unmeasured_sections"] = unmeasuredSectionsToJson(unmeasured);
    std::cout << j.dump(2) << "\n";
    return;
  }
  for (size_t c = 0; c < scan.columns.size(); ++c) std::printf("%-15s %s\n", scan.columns[c].c_str(), text(scan.rows[0][c]).c_str());
  std::printf("\n");
  printTable(sections);
  for (const UnmeasuredSection& u : unmeasured)
    std::printf("section %.3f not measured: %s\n", u.fraction, u.reason.c_str());
}

// `db export`: a query's result to a file, CSV or JSON by flag or by the file's extension.
void runExport(const DbOptions& o) {
  std::string format = o.csv ? "csv" : o.json ? "json" : "";
  if (format.empty()) {
    if (endsWith(o.dest, ".csv")) format = "csv";
    else if (endsWith(o.dest, ".json")) format = "json";
    else throw InvalidInput("db export: give --csv or --json (\"" + o.dest + "\" has neither extension)");
  }
  Database d = openExisting(o, "export");
  const Table t = runQuery(d, o);
  writeTable(o.dest, t, format);
  std::printf("wrote %zu rows to %s\n", t.rows.size(), o.dest.c_str());
}

// `db check`: whether the file is a sailshape database, and its integrity and
// foreign keys as it is (no migration); throws on any problem, one line.
void runCheck(const DbOptions& o) {
  requireExisting(o, "check");
  const bool postgres = isPostgresUrl(o.db);
  std::error_code ec;
  if (!postgres && std::filesystem::file_size(o.db, ec) == 0 && !ec)
    throw DatabaseError("db check: " + o.db + ": not a sailshape database (empty file)");
  Database d(o.db, openOptions(o, false));
  const std::string not_ours = "db check: " + d.path() + ": not a sailshape database";
  const char* kind = postgres ? "a PostgreSQL database" : "an SQLite database";
  const int version = d.userVersion();
  if (version > kSchemaVersion)
    throw DatabaseError("db check: " + d.path() + ": database schema version " + std::to_string(version) +
                        " is newer than this sailshape (" + std::to_string(kSchemaVersion) + ")");
  if (version == 0) {
    const int64_t n = d.tableCount();
    if (n > 0)
      throw DatabaseError(not_ours + " (" + kind + " of another application: " + std::to_string(n) +
                          (n == 1 ? " table" : " tables") + ", no sailshape schema)");
    throw DatabaseError(not_ours + " (" + kind + " without tables; `sailshape db init " + d.path() + "` makes it one)");
  }
  std::vector<std::string> problems;
  try {
    problems = d.integrityCheck();
  } catch (const DatabaseError& e) {
    // SQLite stops the check at pages it cannot read at all.
    throw DatabaseError("db check: " + d.path() + ": damaged: the integrity check stopped at an unreadable page (" +
                        userMessage(e.what()) + ")");
  }
  // integrity_check heads its list with the database it checked; not a problem.
  problems.erase(std::remove_if(problems.begin(), problems.end(),
                                [](const std::string& p) { return p.rfind("*** in database", 0) == 0; }),
                 problems.end());
  if (!problems.empty()) {
    constexpr size_t kListed = 10;
    if (verbose()) {
      for (size_t i = 0; i < std::min(problems.size(), kListed); ++i) std::fprintf(stderr, "  %s\n", problems[i].c_str());
      if (problems.size() > kListed) std::fprintf(stderr, "  ... and %zu more\n", problems.size() - kListed);
    }
    throw DatabaseError("db check: " + d.path() + ": damaged: " + std::to_string(problems.size()) + " integrity problem" +
                        (problems.size() == 1 ? "" : "s") + ", first: " + problems[0] +
                        (verbose() ? "" : " (--verbose lists them)"));
  }
  std::printf("%s: ok (schema version %d)\n", d.path().c_str(), version);
}

// `db copy`: every row of DB into DEST in one transaction on DEST; a DEST file
// this command created is removed again when the copy fails.
void runCopy(const DbOptions& o) {
  Database source = openExisting(o, "copy");
  std::error_code ec;
  const bool new_file = !isPostgresUrl(o.dest) && !std::filesystem::exists(o.dest, ec);
  try {
    Database dest = openSailDatabase(o.dest, openOptions(o, true));
    CopyOptions options;
    options.append = o.append;
    CopyResult r;
    try {
      r = copyStore(source, dest, options);
    } catch (const InvalidInput& e) {
      std::string what = userMessage(e.what());
      const std::string library_advice = "; copy into an empty store, or append to it";
      const size_t advice = what.find(library_advice);
      if (advice == std::string::npos) throw;
      throw InvalidInput("db copy: " + what.replace(advice, library_advice.size(), "; --append adds to it"));
    }
    auto rows = [&](const std::string& table) {
      for (const auto& [name, n] : r.rows_added)
        if (name == table) return n;
      return size_t{0};
    };
    std::printf("copied %zu rows (%zu scans, %zu analyses, %zu sections) from %s to %s\n", r.total_rows, rows("scans"),
                rows("analyses"), rows("sections"), source.path().c_str(), dest.path().c_str());
  } catch (...) {
    if (new_file) {
      for (const char* tail : {"", "-wal", "-shm"}) std::filesystem::remove(o.dest + tail, ec);
    }
    throw;
  }
}

}  // namespace

void addDbCommand(CLI::App& app) {
  auto o = std::make_shared<DbOptions>();
  CLI::App* db = app.add_subcommand(
      "db", "The design-flying database: store scans with their trim steps, query, export, check\n\n"
            "The design-flying database: store scans with their trim steps and analyses, query them, export, check, "
            "back up and copy. DB is an SQLite file (embedded, the default) or a PostgreSQL server's database, "
            "postgresql://USER@HOST:PORT/DBNAME (a loft's shared store: the password comes from ~/.pgpass or "
            "PGPASSWORD, sslmode=require and the like as libpq reads them; the database must exist, `db init` makes "
            "the schema). Every command below takes either.");
  db->require_subcommand(1);
  auto add_db = [&](CLI::App* cmd) {
    cmd->add_option("DB", o->db, "Database: an SQLite file, or postgresql://USER@HOST:PORT/DBNAME")->required();
    cmd->add_option("--busy-timeout", o->busy_timeout_ms,
                    "Milliseconds to wait for another writer's lock before failing (default 5000)")
        ->check(CLI::NonNegativeNumber);
  };

  CLI::App* init = db->add_subcommand("init", "Create a database (or migrate an existing one to this version's schema)");
  add_db(init);
  init->callback([o] {
    Database d = openSailDatabase(o->db, openOptions(*o, true));
    std::printf("%s: schema version %d\n", d.path().c_str(), d.userVersion());
  });

  CLI::App* imp = db->add_subcommand(
      "import", "Store one scan (the JSON of `sailshape analyze --json`, or a cloud) in one transaction");
  add_db(imp);
  addImportOptions(imp, *o);
  imp->callback([o] { runImport(*o); });

  addDbDesignCommand(db, add_db, [o](const char* command) { return openExisting(*o, command); });

  CLI::App* list = db->add_subcommand("list", "List the scans (optionally filtered)");
  add_db(list);
  addFilterOptions(list, *o);
  list->add_flag("--csv", o->csv, "Print CSV");
  list->add_flag("--json", o->json, "Print JSON")->excludes("--csv");
  list->callback([o] {
    Database d = openExisting(*o, "list");
    emit(findScans(d, filterOf(*o)), *o);
  });

  CLI::App* show = db->add_subcommand("show", "Show one scan with its trim step and sections");
  add_db(show);
  show->add_option("SCAN_ID", o->scan_id, "Scan id (see db list)")->required();
  show->add_flag("--json", o->json, "Print JSON");
  show->add_option("--cloud", o->cloud_file,
                   "Also write the scan's stored cloud to this file (.ply, .pcd, .xyz or .csv by its extension): its "
                   "points with their intensity and scan angles, and the scanner's viewpoint, as stored; a scan "
                   "stored with its sail's region (imported for a sail with a design, or by the demo) is written "
                   "within that region, less its mixed pixels; "
                   "`sailshape analyze FILE --scanner MODEL` re-analyses it as the first analysis did");
  show->callback([o] { runShow(*o); });

  CLI::App* query = db->add_subcommand("query", "Query the reference database; prints a table, CSV or JSON");
  add_db(query);
  addQueryOptions(query, *o);
  query->add_flag("--csv", o->csv, "Print CSV");
  query->add_flag("--json", o->json, "Print JSON")->excludes("--csv");
  query->callback([o] {
    Database d = openExisting(*o, "query");
    emit(runQuery(d, *o), *o);
  });

  CLI::App* exp = db->add_subcommand("export", "Write the result of a query (same options as db query) to a file");
  add_db(exp);
  exp->add_option("OUT", o->dest, "Output file")->required();
  addQueryOptions(exp, *o);
  auto* csv = exp->add_flag("--csv", o->csv, "Write CSV");
  auto* json = exp->add_flag("--json", o->json, "Write JSON");
  csv->excludes(json);
  exp->callback([o] { runExport(*o); });

  CLI::App* check = db->add_subcommand("check", "Check the file's integrity and foreign keys; exit 0 only when consistent");
  add_db(check);
  check->callback([o] { runCheck(*o); });

  CLI::App* copy = db->add_subcommand(
      "copy",
      "Copy every row of DB into DEST (SQLite file or PostgreSQL URL) in one transaction\n\n"
      "Copy every row of DB into DEST, in one transaction on DEST: all of it or, on any error, nothing. Either may be "
      "an SQLite file or a PostgreSQL URL, so a tunnel laptop's file goes to the loft's server and the server's "
      "store comes back as a file. DEST is created when it is a missing file; a DEST that holds rows is refused "
      "unless --append is given. Without --append every row keeps its id, so scan ids stay valid.");
  add_db(copy);
  copy->add_option("DEST", o->dest, "Destination: an SQLite file (created when missing) or postgresql://USER@HOST:PORT/DBNAME")
      ->required();
  copy->add_flag("--append", o->append,
                 "Add to a DEST that already holds rows: scans, analyses and calibrations get new ids; campaigns, "
                 "boats, sails, scanner units, sessions and trim steps DEST already has (by name; a trim step by "
                 "session, sail, test and order) are used as they are there");
  copy->callback([o] { runCopy(*o); });

  CLI::App* backup = db->add_subcommand("backup", "Copy an SQLite database file online (SQLite backup API) to DEST");
  add_db(backup);
  backup->add_option("DEST", o->dest, "Destination file (replaced)")->required();
  backup->callback([o] {
    Database d = openExisting(*o, "backup");
    d.backupTo(o->dest);
    std::printf("backed up %s to %s\n", o->db.c_str(), o->dest.c_str());
  });
}

}  // namespace sailshape::cli
