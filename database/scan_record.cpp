#include "database/scan_record.hpp"

#include <algorithm>
#include <limits>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/cloud_blob.hpp"
#include "database/import.hpp"

namespace sailshape {
namespace {

SectionParameters readParameters(const Statement& s, int first) {
  // NULL (not measurable, e.g. no exit angle) stays visible as NaN.
  auto v = [&](int k) { return s.isNull(first + k) ? std::numeric_limits<double>::quiet_NaN() : s.columnDouble(first + k); };
  SectionParameters p;
  p.chord_m = v(0);
  p.camber_pct = v(1);
  p.draft_pct = v(2);
  p.twist_deg = v(3);
  p.twist_rel_deg = v(4);
  p.entry_deg = v(5);
  p.exit_deg = v(6);
  return p;
}

}  // namespace

nlohmann::json regionToJson(const ScanRegion& region) {
  const Eigen::AlignedBox3d& b = region.box;
  return {{"box_m", {b.min().x(), b.max().x(), b.min().y(), b.max().y(), b.min().z(), b.max().z()}},
          {"design_version", region.design_version}};
}

std::optional<ScanRegion> regionFromJson(const nlohmann::json& j) {
  if (!j.is_object() || !j.contains("box_m") || !j["box_m"].is_array() || j["box_m"].size() != 6) return std::nullopt;
  ScanRegion r;
  for (int a = 0; a < 3; ++a) {
    const nlohmann::json &lo = j["box_m"][2 * a], &hi = j["box_m"][2 * a + 1];
    if (!lo.is_number() || !hi.is_number()) return std::nullopt;
    r.box.min()[a] = lo.get<double>();
    r.box.max()[a] = hi.get<double>();
  }
  if (j.contains("design_version") && j["design_version"].is_number_integer()) r.design_version = j["design_version"].get<int>();
  return r;
}

ScanRecord loadScanRecord(Database& db, int64_t scan_id) {
  Statement s = db.prepare(
      "SELECT s.id, s.trim_step_id, s.scanned_at, s.cloud, c.name, t.test, t.step_order, t.awa_deg, sa.name,"
      " sa.design_mesh IS NOT NULL, (SELECT max(a.id) FROM analyses a WHERE a.scan_id = s.id), s.settings, s.region"
      " FROM scans s LEFT JOIN trim_steps t ON t.id = s.trim_step_id LEFT JOIN sessions se ON se.id = t.session_id"
      " LEFT JOIN campaigns c ON c.id = se.campaign_id LEFT JOIN sails sa ON sa.id = t.sail_id WHERE s.id = ?");
  s.bind(1, scan_id);
  if (!s.step()) throw InvalidInput("[loadScanRecord] no scan with id " + std::to_string(scan_id));
  ScanRecord r;
  r.scan_id = s.columnInt(0);
  r.trim_step_id = s.isNull(1) ? 0 : s.columnInt(1);
  r.scanned_at = s.isNull(2) ? "" : s.columnText(2);
  if (!s.isNull(3)) r.cloud = decompressCloud(s.columnBlob(3));
  r.campaign = s.isNull(4) ? "" : s.columnText(4);
  r.test = s.isNull(5) ? "" : s.columnText(5);
  r.step = s.isNull(6) ? 0 : static_cast<int>(s.columnInt(6));
  if (!s.isNull(7)) r.awa_deg = s.columnDouble(7);
  r.sail = s.isNull(8) ? "" : s.columnText(8);
  r.has_design = !s.isNull(9) && s.columnInt(9) != 0;
  r.analysis_id = s.isNull(10) ? 0 : s.columnInt(10);
  if (!s.isNull(11)) r.settings = nlohmann::json::parse(s.columnText(11), nullptr, false);
  if (r.settings.is_discarded()) r.settings = nullptr;
  if (!s.isNull(12)) r.region = regionFromJson(nlohmann::json::parse(s.columnText(12), nullptr, false));
  Statement g = db.prepare("SELECT id FROM registrations WHERE scan_id = ? LIMIT 1");
  g.bind(1, scan_id);
  if (g.step()) r.registration = scanTransform(db, scan_id);
  if (r.analysis_id == 0) return r;

  Statement a = db.prepare("SELECT params FROM analyses WHERE id = ?");
  a.bind(1, r.analysis_id);
  if (a.step() && !a.isNull(0)) r.analysis_params = nlohmann::json::parse(a.columnText(0), nullptr, false);
  if (r.analysis_params.is_discarded()) r.analysis_params = nullptr;

  r.sections.sections = analysisSections(db, r.analysis_id);
  r.sections.unmeasured = unmeasuredSections(db, r.analysis_id);
  r.surface = analysisSurface(db, r.analysis_id);
  return r;
}

std::vector<Section> analysisSections(Database& db, int64_t analysis_id) {
  Statement x = db.prepare(
      "SELECT fraction, chord_m, camber_pct, draft_pct, twist_deg, twist_rel_deg, entry_deg, exit_deg, u_chord_m,"
      " u_camber_pct, u_draft_pct, u_twist_deg, u_twist_rel_deg, u_entry_deg, u_exit_deg, plane_tilt_deg, converged,"
      " curve FROM sections WHERE analysis_id = ? ORDER BY fraction");
  x.bind(1, analysis_id);
  std::vector<Section> sections;
  while (x.step()) {
    Section sec;
    sec.fraction = x.columnDouble(0);
    sec.value = readParameters(x, 1);
    sec.uncertainty = readParameters(x, 8);
    sec.plane_tilt_deg = x.isNull(15) ? 0.0 : x.columnDouble(15);
    sec.converged = x.columnInt(16) != 0;
    if (!x.isNull(17)) sec.curve = unpackCurve(x.columnBlob(17));
    if (!sec.curve.empty()) {
      sec.luff_point = sec.curve.front();
      sec.leech_point = sec.curve.back();
    }
    sec.curve_samples = sec.curve.size();
    sections.push_back(std::move(sec));
  }
  return sections;
}

std::optional<ScanSummary> scanSummary(Database& db, int64_t scan_id) {
  Statement s = db.prepare(
      "SELECT trim_step_id, scanned_at, (SELECT max(a.id) FROM analyses a WHERE a.scan_id = s.id)"
      " FROM scans s WHERE s.id = ?");
  s.bind(1, scan_id);
  if (!s.step()) return std::nullopt;
  ScanSummary summary;
  summary.trim_step_id = s.isNull(0) ? 0 : s.columnInt(0);
  summary.scanned_at = s.isNull(1) ? "" : s.columnText(1);
  summary.analysis_id = s.isNull(2) ? 0 : s.columnInt(2);
  return summary;
}

std::optional<Cloud> scanCloud(Database& db, int64_t scan_id) {
  Statement s = db.prepare("SELECT cloud FROM scans WHERE id = ?");
  s.bind(1, scan_id);
  if (!s.step() || s.isNull(0)) return std::nullopt;
  return decompressCloud(s.columnBlob(0));
}

std::string analysisOutlineJson(Database& db, int64_t analysis_id) {
  Statement s = db.prepare("SELECT sail FROM analyses WHERE id = ?");
  s.bind(1, analysis_id);
  return s.step() && !s.isNull(0) ? s.columnText(0) : std::string();
}

std::optional<Mesh> analysisSurface(Database& db, int64_t analysis_id) {
  Statement s = db.prepare("SELECT surface_mesh FROM analyses WHERE id = ?");
  s.bind(1, analysis_id);
  if (!s.step() || s.isNull(0)) return std::nullopt;
  return unpackMesh(s.columnBlob(0));
}

int64_t latestAnalysisId(Database& db, int64_t scan_id) {
  Statement a = db.prepare("SELECT max(id) FROM analyses WHERE scan_id = ?");
  a.bind(1, scan_id);
  return a.step() && !a.isNull(0) ? a.columnInt(0) : 0;
}

std::vector<UnmeasuredSection> unmeasuredSections(Database& db, int64_t analysis_id) {
  Statement s = db.prepare("SELECT diagnostics FROM analyses WHERE id = ?");
  s.bind(1, analysis_id);
  std::vector<UnmeasuredSection> out;
  if (!s.step() || s.isNull(0)) return out;
  const nlohmann::json d = nlohmann::json::parse(s.columnText(0), nullptr, false);
  if (d.is_discarded() || !d.is_object() || !d.contains("unmeasured_sections")) return out;
  for (const nlohmann::json& x : d["unmeasured_sections"])
    if (x.is_object() && x.value("fraction", nlohmann::json()).is_number() && x.value("reason", nlohmann::json()).is_string())
      out.push_back({x["fraction"].get<double>(), x["reason"].get<std::string>()});
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.fraction < b.fraction; });
  return out;
}

}  // namespace sailshape
