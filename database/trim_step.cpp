#include "database/trim_step.hpp"

#include "database/catalog.hpp"

namespace sailshape {
namespace {

std::string textOr(const Statement& s, int column) { return s.isNull(column) ? std::string() : s.columnText(column); }
std::optional<double> optionalReal(const Statement& s, int column) {
  return s.isNull(column) ? std::nullopt : std::optional<double>(s.columnDouble(column));
}

}  // namespace

std::optional<TrimStepContext> trimStepContext(Database& db, int64_t trim_step_id) {
  Statement s = db.prepare(
      "SELECT c.name, c.kind, c.place, c.start_date, se.name, se.started_at, b.name, b.class, sa.name, sa.type,"
      " sa.size_variant, sa.designer, sa.version, sa.design_mesh, t.test"
      " FROM trim_steps t JOIN sessions se ON se.id = t.session_id JOIN campaigns c ON c.id = se.campaign_id"
      " JOIN sails sa ON sa.id = t.sail_id LEFT JOIN boats b ON b.id = sa.boat_id WHERE t.id = ?");
  s.bind(1, trim_step_id);
  if (!s.step()) return std::nullopt;
  TrimStepContext c;
  c.campaign = textOr(s, 0);
  c.campaign_kind = textOr(s, 1);
  c.place = textOr(s, 2);
  c.campaign_start = textOr(s, 3);
  c.session = textOr(s, 4);
  c.session_started = textOr(s, 5);
  c.boat = textOr(s, 6);
  c.boat_class = textOr(s, 7);
  c.sail = textOr(s, 8);
  c.sail_type = textOr(s, 9);
  c.size_variant = textOr(s, 10);
  c.designer = textOr(s, 11);
  c.version = textOr(s, 12);
  if (!s.isNull(13)) c.design_mesh = unpackMesh(s.columnBlob(13));
  c.test = textOr(s, 14);
  return c;
}

std::optional<TrimStepConditions> trimStepConditions(Database& db, int64_t trim_step_id) {
  Statement s = db.prepare(
      "SELECT step_order, awa_deg, aws_m_s, drive_n, side_n, heel_moment_nm FROM trim_steps WHERE id = ?");
  s.bind(1, trim_step_id);
  if (!s.step()) return std::nullopt;
  TrimStepConditions c;
  c.step_order = static_cast<int>(s.columnInt(0));
  c.awa_deg = optionalReal(s, 1);
  c.aws_m_s = optionalReal(s, 2);
  c.drive_n = optionalReal(s, 3);
  c.side_n = optionalReal(s, 4);
  c.heel_moment_nm = optionalReal(s, 5);
  Statement controls = db.prepare("SELECT name, value FROM control_settings WHERE trim_step_id = ? ORDER BY name");
  controls.bind(1, trim_step_id);
  while (controls.step()) c.controls[controls.columnText(0)] = controls.columnDouble(1);
  return c;
}

std::vector<TestStep> testSteps(Database& db, const std::string& test, const std::string& sail) {
  Statement s = db.prepare(
      "SELECT t.id, sa.name, t.session_id, (SELECT max(sc.id) FROM scans sc WHERE sc.trim_step_id = t.id"
      " AND EXISTS (SELECT 1 FROM analyses a WHERE a.scan_id = sc.id))"
      " FROM trim_steps t JOIN sails sa ON sa.id = t.sail_id WHERE t.test = ? AND (? = '' OR sa.name = ?)"
      " ORDER BY t.step_order, t.id");
  s.bind(1, test).bind(2, sail).bind(3, sail);
  std::vector<TestStep> steps;
  while (s.step()) {
    TestStep t;
    t.trim_step_id = s.columnInt(0);
    t.sail = s.columnText(1);
    t.session_id = s.columnInt(2);
    t.analysed_scan_id = s.isNull(3) ? 0 : s.columnInt(3);
    steps.push_back(std::move(t));
  }
  return steps;
}

}  // namespace sailshape
