#include "reports/report_data.hpp"

#include <cmath>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"
#include "database/scan_record.hpp"
#include "database/trim_step.hpp"

namespace sailshape {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Sail, boat, session and campaign of a trim step.
void loadContext(Database& db, int64_t trim_step_id, ReportData& data) {
  std::optional<TrimStepContext> c = trimStepContext(db, trim_step_id);
  if (!c) throw InvalidInput("[loadReport] trim step " + std::to_string(trim_step_id) + " not found");
  static_cast<TrimStepContext&>(data) = std::move(*c);
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
  const std::optional<ScanSummary> scan = scanSummary(db, scan_id);
  if (!scan) throw InvalidInput(std::string("[") + function + "] no scan with id " + std::to_string(scan_id));
  if (scan->trim_step_id == 0)
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) + " belongs to no trim step");
  if (scan->analysis_id == 0)
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) +
                       " has no analysis (import it with its `sailshape analyze --json` document)");
  ReportStep step;
  step.scan_id = scan_id;
  step.trim_step_id = scan->trim_step_id;
  step.analysis_id = scan->analysis_id;
  step.scanned_at = scan->scanned_at;
  if (std::optional<Cloud> cloud = scanCloud(db, scan_id)) step.cloud = std::move(*cloud);
  if (std::optional<TrimStepConditions> c = trimStepConditions(db, step.trim_step_id)) {
    step.step_order = c->step_order;
    step.awa_deg = c->awa_deg;
    step.aws_m_s = c->aws_m_s;
    step.drive_n = c->drive_n;
    step.side_n = c->side_n;
    step.heel_moment_nm = c->heel_moment_nm;
    step.controls = std::move(c->controls);
  }
  for (Section& s : analysisSections(db, step.analysis_id)) {
    ReportSection r;
    r.fraction = s.fraction;
    r.value = s.value;
    r.uncertainty = s.uncertainty;
    r.converged = s.converged;
    r.curve = std::move(s.curve);
    step.sections.push_back(std::move(r));
  }
  if (step.sections.empty())
    throw InvalidInput(std::string("[") + function + "] scan " + std::to_string(scan_id) + " has an analysis without sections");
  step.unmeasured = unmeasuredSections(db, step.analysis_id);
  step.outline = parseOutline(analysisOutlineJson(db, step.analysis_id), step.analysis_id, function);
  step.surface = analysisSurface(db, step.analysis_id);
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
  std::set<std::string> sails;
  std::set<int64_t> sessions;
  std::vector<int64_t> scans;
  const std::vector<TestStep> steps = testSteps(db, test, sail);
  for (const TestStep& t : steps) {
    sails.insert(t.sail);
    sessions.insert(t.session_id);
    if (t.analysed_scan_id != 0) scans.push_back(t.analysed_scan_id);
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
  loadContext(db, steps.front().trim_step_id, data);
  for (int64_t id : scans) data.steps.push_back(loadStep(db, id, "loadTestReport"));
  return data;
}

}  // namespace sailshape
