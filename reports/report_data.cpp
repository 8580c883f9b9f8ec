#include "reports/report_data.hpp"

#include <cmath>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/cloud_blob.hpp"
#include "database/import.hpp"
#include "database/scan_record.hpp"

namespace sailshape {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string textOr(const Statement& s, int column) { return s.isNull(column) ? std::string() : s.columnText(column); }
double realOr(const Statement& s, int column) { return s.isNull(column) ? kNaN : s.columnDouble(column); }
std::optional<double> optionalReal(const Statement& s, int column) {
  return s.isNull(column) ? std::nullopt : std::optional<double>(s.columnDouble(column));
}

// Sail, boat, session and campaign of a trim step.
void loadContext(Database& db, int64_t trim_step_id, ReportData& data) {
  Statement s = db.prepare(
      "SELECT c.name, c.kind, c.place, c.start_date, se.name, se.started_at, b.name, b.class, sa.name, sa.type,"
      " sa.size_variant, sa.designer, sa.version, sa.design_mesh, t.test"
      " FROM trim_steps t JOIN sessions se ON se.id = t.session_id JOIN campaigns c ON c.id = se.campaign_id"
      " JOIN sails sa ON sa.id = t.sail_id LEFT JOIN boats b ON b.id = sa.boat_id WHERE t.id = ?");
  s.bind(1, trim_step_id);
  if (!s.step()) throw InvalidInput("[loadReport] trim step " + std::to_string(trim_step_id) + " not found");
  data.campaign = textOr(s, 0);
  data.campaign_kind = textOr(s, 1);
  data.place = textOr(s, 2);
  data.campaign_start = textOr(s, 3);
  data.session = textOr(s, 4);
  data.session_started = textOr(s, 5);
  data.boat = textOr(s, 6);
  data.boat_class = textOr(s, 7);
  data.sail = textOr(s, 8);
  data.sail_type = textOr(s, 9);
  data.size_variant = textOr(s, 10);
  data.designer = textOr(s, 11);
  data.version = textOr(s, 12);
  if (!s.isNull(13)) data.design_mesh = unpackMesh(s.columnBlob(13));
  data.test = textOr(s, 14);
}

// The outline stored with an analysis: `sail` as `sailshape analyze --json` writes
// it, with its `luff` object inside (database/import.cpp). A value missing or not a
// number stays NaN; the stored text not being JSON is a damaged file.
ReportOutline parseOutline(const std::string& text, int64_t analysis_id, const char* function) {
  ReportOutline o;
  if (text.empty()) return o;
  const nlohmann::json sail = nlohmann::json::parse(text, nullptr, false);
  if (sail.is_discarded() || !sail.is_object())
    throw InvalidInput(std::string("[") + function + "] analysis " + std::to_string(analysis_id) +
                       ": its stored outline (analyses.sail) is not a JSON object");
  auto read = [](const nlohmann::json& j, const char* key, OutlineMeasure& m) {
    auto number = [&](const nlohmann::json& from) {
      auto it = from.find(key);
      return it != from.end() && it->is_number() ? it->get<double>() : kNaN;
    };
    m.value = number(j);
    auto u = j.find("uncertainty");
    if (u != j.end() && u->is_object()) m.sigma = number(*u);
  };
  read(sail, "luff_length_m", o.luff_length_m);
  read(sail, "leech_length_m", o.leech_length_m);
  read(sail, "foot_length_m", o.foot_length_m);
  read(sail, "top_length_m", o.top_length_m);
  read(sail, "area_m2", o.area_m2);
  if (auto beam = sail.find("beam_footprint_m"); beam != sail.end() && beam->is_number())
    o.beam_footprint_m = beam->get<double>();
  auto luff = sail.find("luff");
  if (luff != sail.end() && luff->is_object()) {
    read(*luff, "lufa_sag_pct", o.lufa_sag_pct);
    read(*luff, "lufa_position_pct", o.lufa_position_pct);
    read(*luff, "lusw_sag_pct", o.lusw_sag_pct);
    read(*luff, "lusw_position_pct", o.lusw_position_pct);
  }
  return o;
}

ReportStep loadStep(Database& db, int64_t scan_id, const char* function) {
  Statement s = db.prepare(
      "SELECT sc.trim_step_id, sc.scanned_at, sc.cloud, t.step_order, t.awa_deg, t.aws_m_s, t.drive_n, t.side_n,"
      " t.heel_moment_nm, (SELECT max(a.id) FROM analyses a WHERE a.scan_id = sc.id)"
      " FROM scans sc LEFT JOIN trim_steps t ON t.id = sc.trim_step_id WHERE sc.id = ?");
  s.bind(1, scan_id);
  if (!s.step()) throw InvalidInput(std::string("[") + function + "] no scan with id " + std::to_string(scan_id));
  if (s.isNull(0))
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) + " belongs to no trim step");
  if (s.isNull(9))
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) +
                       " has no analysis (import it with its `sailshape analyze --json` document)");
  ReportStep step;
  step.scan_id = scan_id;
  step.trim_step_id = s.columnInt(0);
  step.scanned_at = textOr(s, 1);
  if (!s.isNull(2)) step.cloud = decompressCloud(s.columnBlob(2));
  step.step_order = static_cast<int>(s.columnInt(3));
  step.awa_deg = optionalReal(s, 4);
  step.aws_m_s = optionalReal(s, 5);
  step.drive_n = optionalReal(s, 6);
  step.side_n = optionalReal(s, 7);
  step.heel_moment_nm = optionalReal(s, 8);
  step.analysis_id = s.columnInt(9);

  Statement c = db.prepare("SELECT name, value FROM control_settings WHERE trim_step_id = ? ORDER BY name");
  c.bind(1, step.trim_step_id);
  while (c.step()) step.controls[c.columnText(0)] = c.columnDouble(1);

  Statement sec = db.prepare(
      "SELECT fraction, chord_m, camber_pct, draft_pct, twist_deg, twist_rel_deg, entry_deg, exit_deg, u_chord_m,"
      " u_camber_pct, u_draft_pct, u_twist_deg, u_twist_rel_deg, u_entry_deg, u_exit_deg, converged, curve"
      " FROM sections WHERE analysis_id = ? ORDER BY fraction");
  sec.bind(1, step.analysis_id);
  while (sec.step()) {
    ReportSection r;
    r.fraction = sec.columnDouble(0);
    auto fill = [&](SectionParameters& p, int first) {
      p.chord_m = realOr(sec, first);
      p.camber_pct = realOr(sec, first + 1);
      p.draft_pct = realOr(sec, first + 2);
      p.twist_deg = realOr(sec, first + 3);
      p.twist_rel_deg = realOr(sec, first + 4);
      p.entry_deg = realOr(sec, first + 5);
      p.exit_deg = realOr(sec, first + 6);
    };
    fill(r.value, 1);
    fill(r.uncertainty, 8);
    r.converged = sec.columnInt(15) != 0;
    if (!sec.isNull(16)) r.curve = unpackCurve(sec.columnBlob(16));
    step.sections.push_back(std::move(r));
  }
  if (step.sections.empty())
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) + " has an analysis without sections");
  step.unmeasured = unmeasuredSections(db, step.analysis_id);
  Statement a = db.prepare("SELECT sail FROM analyses WHERE id = ?");
  a.bind(1, step.analysis_id);
  if (a.step()) step.outline = parseOutline(textOr(a, 0), step.analysis_id, function);
  return step;
}

}  // namespace

ReportOutline reportOutline(const SailOutline& o, const LuffCurve& l) {
  ReportOutline r;
  const SailOutline::Uncertainty& u = o.uncertainty;
  r.luff_length_m = {o.luff_length_m, u.luff_length_m};
  r.leech_length_m = {o.leech_length_m, u.leech_length_m};
  r.foot_length_m = {o.foot_length_m, u.foot_length_m};
  if (o.has_peak) r.top_length_m = {o.top_length_m, u.top_length_m};
  r.area_m2 = {o.area_m2, u.area_m2};
  r.lufa_sag_pct = {l.lufa_sag_pct, l.uncertainty.lufa_sag_pct};
  r.lufa_position_pct = {l.lufa_position_pct, l.uncertainty.lufa_position_pct};
  r.lusw_sag_pct = {l.lusw_sag_pct, l.uncertainty.lusw_sag_pct};
  r.lusw_position_pct = {l.lusw_position_pct, l.uncertainty.lusw_position_pct};
  return r;
}

ReportData loadScanReport(Database& db, int64_t scan_id) {
  ReportData data;
  ReportStep step = loadStep(db, scan_id, "loadScanReport");
  loadContext(db, step.trim_step_id, data);
  data.steps.push_back(std::move(step));
  return data;
}

ReportData loadTestReport(Database& db, const std::string& test, const std::string& sail) {
  if (test.empty()) throw InvalidInput("[loadTestReport] test name must not be empty");
  Statement s = db.prepare(
      "SELECT t.id, sa.name, t.session_id, (SELECT max(sc.id) FROM scans sc WHERE sc.trim_step_id = t.id"
      " AND EXISTS (SELECT 1 FROM analyses a WHERE a.scan_id = sc.id))"
      " FROM trim_steps t JOIN sails sa ON sa.id = t.sail_id WHERE t.test = ? AND (? = '' OR sa.name = ?)"
      " ORDER BY t.step_order, t.id");
  s.bind(1, test).bind(2, sail).bind(3, sail);
  std::set<std::string> sails;
  std::set<int64_t> sessions;
  std::vector<int64_t> scans;
  int64_t first_step = 0;
  while (s.step()) {
    sails.insert(s.columnText(1));
    sessions.insert(s.columnInt(2));
    if (!first_step) first_step = s.columnInt(0);
    if (!s.isNull(3)) scans.push_back(s.columnInt(3));
  }
  if (sails.empty())
    throw InvalidInput("[loadTestReport] no test named \"" + test + "\"" + (sail.empty() ? "" : " for sail \"" + sail + "\""));
  if (sails.size() > 1) {
    std::string names;
    for (const auto& n : sails) names += (names.empty() ? "" : ", ") + n;
    throw InvalidInput("[loadTestReport] test \"" + test + "\" covers several sails (" + names + "); name one");
  }
  if (sessions.size() > 1)
    throw InvalidInput("[loadTestReport] test \"" + test + "\" of sail \"" + *sails.begin() + "\" spans " +
                       std::to_string(sessions.size()) + " sessions; one report covers one session's test");
  if (scans.empty()) throw InvalidInput("[loadTestReport] test \"" + test + "\" has no analysed scan");
  ReportData data;
  loadContext(db, first_step, data);
  for (int64_t id : scans) data.steps.push_back(loadStep(db, id, "loadTestReport"));
  return data;
}

}  // namespace sailshape
