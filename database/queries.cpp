#include "database/queries.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "analysis/core/errors.hpp"
#include "database/dialect.hpp"
#include "database/scan_record.hpp"

namespace sailshape {
namespace {

const char* const kFrom =
    " FROM scans s"
    " JOIN trim_steps t ON t.id = s.trim_step_id"
    " JOIN sessions se ON se.id = t.session_id"
    " JOIN campaigns c ON c.id = se.campaign_id"
    " JOIN sails sa ON sa.id = t.sail_id"
    " LEFT JOIN boats b ON b.id = sa.boat_id";

// The controls column carries the trim step's id until fillControls() replaces
// it by its settings, "name=value;..." by name, each value as SQLite writes a
// REAL: built here rather than by SQL so that both backends answer alike.
const char* const kControls = "t.id";

// The latest analysis of scan s.
const char* const kLatestAnalysis = "(SELECT max(a.id) FROM analyses a WHERE a.scan_id = s.id)";

struct Where {
  std::string sql;
  std::vector<Value> args;
  void add(const std::string& clause, Value v) {
    sql += (sql.empty() ? " WHERE " : " AND ") + clause;
    args.push_back(std::move(v));
  }
  void add(const std::string& clause) { sql += (sql.empty() ? " WHERE " : " AND ") + clause; }
};

Where buildWhere(const ScanFilter& f, bool with_scan) {
  Where w;
  if (f.scan_id) {
    if (!with_scan) throw InvalidInput("[query] a scan id does not apply to a trim-step query");
    w.add("s.id = ?", *f.scan_id);
  }
  if (f.boat) w.add("b.name = ?", *f.boat);
  if (f.sail) w.add("sa.name = ?", *f.sail);
  if (f.sail_type) w.add("sa.type = ?", *f.sail_type);
  if (f.campaign) w.add("c.name = ?", *f.campaign);
  if (f.test) w.add("t.test = ?", *f.test);
  if (f.awa_min_deg) w.add("t.awa_deg >= ?", *f.awa_min_deg);
  if (f.awa_max_deg) w.add("t.awa_deg <= ?", *f.awa_max_deg);
  if (f.awa_min_deg && f.awa_max_deg && *f.awa_min_deg > *f.awa_max_deg)
    throw InvalidInput("[query] awa_min_deg " + std::to_string(*f.awa_min_deg) + " is above awa_max_deg " +
                       std::to_string(*f.awa_max_deg));
  if ((f.control_min || f.control_max) && !f.control)
    throw InvalidInput("[query] a control range needs the control's name");
  if (f.control) {
    w.add("EXISTS (SELECT 1 FROM control_settings cf WHERE cf.trim_step_id = t.id AND cf.name = ?", *f.control);
    if (f.control_min) {
      w.sql += " AND cf.value >= ?";
      w.args.push_back(*f.control_min);
    }
    if (f.control_max) {
      w.sql += " AND cf.value <= ?";
      w.args.push_back(*f.control_max);
    }
    w.sql += ")";
  }
  return w;
}

void bindAll(Statement& s, const std::vector<Value>& args, int first = 1) {
  for (size_t i = 0; i < args.size(); ++i) {
    const int k = first + static_cast<int>(i);
    const Value& v = args[i];
    if (std::holds_alternative<int64_t>(v)) s.bind(k, std::get<int64_t>(v));
    else if (std::holds_alternative<double>(v)) s.bind(k, std::get<double>(v));
    else if (std::holds_alternative<std::string>(v)) s.bind(k, std::get<std::string>(v));
    else s.bindNull(k);
  }
}

Table collect(Statement& s) {
  Table t;
  for (int c = 0; c < s.columnCount(); ++c) t.columns.push_back(s.columnName(c));
  while (s.step()) {
    std::vector<Value> row;
    row.reserve(t.columns.size());
    for (int c = 0; c < s.columnCount(); ++c) {
      if (s.isNull(c)) row.emplace_back();
      else if (s.isInteger(c)) row.emplace_back(s.columnInt(c));
      else if (s.isFloat(c)) row.emplace_back(s.columnDouble(c));
      else row.emplace_back(s.columnText(c));
    }
    t.rows.push_back(std::move(row));
  }
  return t;
}

void fillControls(Database& db, Table& table) {
  const auto column = std::find(table.columns.begin(), table.columns.end(), "controls");
  if (column == table.columns.end()) return;
  const size_t c = static_cast<size_t>(column - table.columns.begin());
  std::vector<int64_t> ids;
  for (const auto& row : table.rows)
    if (const auto* id = std::get_if<int64_t>(&row[c])) ids.push_back(*id);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  std::map<int64_t, std::string> text;
  constexpr size_t kPerQuery = 500;  // ids in one IN list
  for (size_t first = 0; first < ids.size(); first += kPerQuery) {
    std::string list;
    for (size_t i = first; i < std::min(ids.size(), first + kPerQuery); ++i) list += (list.empty() ? "" : ",") + std::to_string(ids[i]);
    Statement s = db.prepare("SELECT trim_step_id, name, value FROM control_settings WHERE trim_step_id IN (" + list +
                             ") ORDER BY trim_step_id, name");
    while (s.step()) {
      std::string& t = text[s.columnInt(0)];
      t += (t.empty() ? "" : ";") + s.columnText(1) + "=" + detail::sqliteRealText(s.columnDouble(2));
    }
  }
  for (auto& row : table.rows) {
    const auto* id = std::get_if<int64_t>(&row[c]);
    if (!id) continue;
    const auto found = text.find(*id);
    if (found == text.end()) row[c] = std::monostate{};
    else row[c] = found->second;
  }
}

std::string sectionColumns(const std::string& alias) {
  std::string cols;
  for (const auto& p : sectionParameterNames()) cols += ", " + alias + "." + p;
  for (const auto& p : sectionParameterNames()) cols += ", " + alias + ".u_" + p;
  return cols;
}

void checkParameter(const std::string& parameter, const char* function) {
  const auto& names = sectionParameterNames();
  if (std::find(names.begin(), names.end(), parameter) == names.end())
    throw InvalidInput(std::string("[") + function + "] unknown section parameter \"" + parameter +
                       "\" (chord_m, camber_pct, draft_pct, twist_deg, twist_rel_deg, entry_deg, exit_deg)");
}

const char* const kScanColumns =
    "SELECT s.id AS scan_id, c.name AS campaign, b.name AS boat, sa.name AS sail, sa.type AS sail_type, t.test AS test,"
    " t.step_order AS step, t.awa_deg, t.aws_m_s, t.drive_n, t.side_n, t.heel_moment_nm, s.point_count, s.scanned_at, ";

}  // namespace

const std::vector<std::string>& sectionParameterNames() {
  static const std::vector<std::string> names = {"chord_m",       "camber_pct", "draft_pct", "twist_deg",
                                                 "twist_rel_deg", "entry_deg",  "exit_deg"};
  return names;
}

Table findScans(Database& db, const ScanFilter& filter) {
  const Where w = buildWhere(filter, true);
  Statement s = db.prepare(std::string(kScanColumns) + kControls + " AS controls" + kFrom + w.sql +
                           " ORDER BY c.name, t.test, t.step_order, s.id");
  bindAll(s, w.args);
  Table t = collect(s);
  fillControls(db, t);
  return t;
}

Table findSections(Database& db, const ScanFilter& filter) {
  const Where w = buildWhere(filter, true);
  Statement s = db.prepare("SELECT s.id AS scan_id, sa.name AS sail, t.test AS test, t.step_order AS step, t.awa_deg,"
                           " x.fraction" + sectionColumns("x") + ", x.converged" + kFrom +
                           " JOIN sections x ON x.analysis_id = " + kLatestAnalysis + w.sql +
                           " ORDER BY c.name, t.test, t.step_order, s.id, x.fraction");
  bindAll(s, w.args);
  return collect(s);
}

Table parameterEvolution(Database& db, const std::string& test, const std::string& parameter, double fraction,
                         const ScanFilter& filter) {
  checkParameter(parameter, "parameterEvolution");
  if (!(fraction > 0 && fraction < 1))
    throw InvalidInput("[parameterEvolution] fraction must be in (0, 1) (got " + std::to_string(fraction) + ")");
  ScanFilter f = filter;
  f.test = test;
  const Where w = buildWhere(f, true);
  Statement s = db.prepare(
      "SELECT t.step_order AS step, t.awa_deg, s.id AS scan_id, sa.name AS sail, x.fraction, x." + parameter +
      " AS value, x.u_" + parameter + " AS uncertainty, " + kControls + " AS controls" + kFrom +
      " JOIN sections x ON x.id = (SELECT y.id FROM sections y WHERE y.analysis_id = " + kLatestAnalysis +
      " ORDER BY abs(y.fraction - ?), y.fraction LIMIT 1)" + w.sql + " ORDER BY t.step_order, s.id");
  s.bind(1, fraction);
  bindAll(s, w.args, 2);
  Table t = collect(s);
  fillControls(db, t);
  // A step whose analysis was asked for a section nearer `fraction` than the one
  // found, and could not measure it, has no value there: the nearest measured one
  // belongs to another height.
  for (auto& row : t.rows) {
    const auto* scan_id = std::get_if<int64_t>(&row[2]);
    const auto* found = std::get_if<double>(&row[4]);
    if (!scan_id || !found) continue;
    const int64_t analysis_id = latestAnalysisId(db, *scan_id);
    if (analysis_id == 0) continue;
    for (const UnmeasuredSection& u : unmeasuredSections(db, analysis_id))
      if (std::abs(u.fraction - fraction) < std::abs(*found - fraction)) {
        row[4] = row[5] = row[6] = std::monostate{};
        break;
      }
  }
  return t;
}

Table compareSails(Database& db, const std::string& sail_a, const std::string& sail_b, double awa_deg,
                   double tolerance_deg) {
  if (!(tolerance_deg >= 0))
    throw InvalidInput("[compareSails] tolerance_deg must be >= 0 (got " + std::to_string(tolerance_deg) + ")");
  if (sail_a == sail_b) throw InvalidInput("[compareSails] two different sails are needed (got \"" + sail_a + "\" twice)");
  Table out;
  out.columns.push_back("fraction");
  std::map<long long, std::vector<Value>> by_fraction;  // key: fraction in 1e-6 steps
  const size_t per_sail = 2 + sectionParameterNames().size();
  for (int k = 0; k < 2; ++k) {
    const std::string& sail = k == 0 ? sail_a : sail_b;
    out.columns.push_back(sail + ".scan_id");
    out.columns.push_back(sail + ".awa_deg");
    for (const auto& p : sectionParameterNames()) out.columns.push_back(sail + "." + p);
    Statement nearest = db.prepare(
        "SELECT s.id, t.awa_deg FROM scans s JOIN trim_steps t ON t.id = s.trim_step_id JOIN sails sa ON sa.id = t.sail_id"
        " WHERE sa.name = ? AND t.awa_deg BETWEEN ? AND ? AND EXISTS (SELECT 1 FROM analyses a WHERE a.scan_id = s.id)"
        " ORDER BY abs(t.awa_deg - ?), s.id DESC LIMIT 1");
    nearest.bind(1, sail).bind(2, awa_deg - tolerance_deg).bind(3, awa_deg + tolerance_deg).bind(4, awa_deg);
    if (!nearest.step()) continue;  // no scan of this sail near that AWA: its columns stay empty
    const int64_t scan_id = nearest.columnInt(0);
    const double awa = nearest.columnDouble(1);
    std::string cols;
    for (const auto& p : sectionParameterNames()) cols += ", x." + p;
    Statement sec = db.prepare("SELECT x.fraction" + cols + " FROM scans s JOIN sections x ON x.analysis_id = " +
                               kLatestAnalysis + " WHERE s.id = ? ORDER BY x.fraction");
    sec.bind(1, scan_id);
    while (sec.step()) {
      const double fraction = sec.columnDouble(0);
      auto& row = by_fraction[std::llround(fraction * 1e6)];
      if (row.empty()) row.resize(1 + 2 * per_sail);
      row[0] = fraction;
      const size_t base = 1 + k * per_sail;
      row[base] = scan_id;
      row[base + 1] = awa;
      for (size_t p = 0; p < sectionParameterNames().size(); ++p)
        if (!sec.isNull(1 + int(p))) row[base + 2 + p] = sec.columnDouble(1 + int(p));
    }
  }
  for (auto& [key, row] : by_fraction) out.rows.push_back(std::move(row));
  return out;
}

Table bestTrimSteps(Database& db, double awa_min_deg, double awa_max_deg, TrimCriterion criterion, int limit,
                    const ScanFilter& filter) {
  if (!(awa_min_deg <= awa_max_deg))
    throw InvalidInput("[bestTrimSteps] awa_min_deg " + std::to_string(awa_min_deg) + " is above awa_max_deg " +
                       std::to_string(awa_max_deg));
  if (limit < 1) throw InvalidInput("[bestTrimSteps] limit must be >= 1 (got " + std::to_string(limit) + ")");
  ScanFilter f = filter;
  f.awa_min_deg = awa_min_deg;
  f.awa_max_deg = awa_max_deg;
  Where w = buildWhere(f, false);
  w.add(criterion == TrimCriterion::Drive ? "t.drive_n IS NOT NULL"
                                          : "t.drive_n IS NOT NULL AND t.side_n IS NOT NULL AND t.side_n <> 0");
  Statement s = db.prepare(
      std::string("SELECT t.id AS trim_step_id, c.name AS campaign, sa.name AS sail, t.test AS test, t.step_order AS step,"
                  " t.awa_deg, t.drive_n, t.side_n, t.drive_n / nullif(t.side_n, 0) AS drive_side, ") +
      kControls + " AS controls FROM trim_steps t JOIN sessions se ON se.id = t.session_id"
      " JOIN campaigns c ON c.id = se.campaign_id JOIN sails sa ON sa.id = t.sail_id LEFT JOIN boats b ON b.id = sa.boat_id" +
      w.sql + (criterion == TrimCriterion::Drive ? " ORDER BY t.drive_n DESC" : " ORDER BY drive_side DESC") +
      ", t.id LIMIT ?");
  bindAll(s, w.args);
  s.bind(static_cast<int>(w.args.size()) + 1, static_cast<int64_t>(limit));
  Table t = collect(s);
  fillControls(db, t);
  return t;
}

}  // namespace sailshape
