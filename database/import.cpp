#include "database/import.hpp"
#include "database/catalog.hpp"

#include <cmath>
#include <cstring>

#include "analysis/core/errors.hpp"
#include "analysis/core/plausible.hpp"
#include "database/catalog.hpp"
#include "database/cloud_blob.hpp"

namespace sailshape {
namespace {

const char* const kParameters[] = {"chord_m", "camber_pct", "draft_pct", "twist_deg", "twist_rel_deg", "entry_deg",
                                   "exit_deg"};

int64_t findOrCreate(Database& db, const std::string& select, const std::string& insert, const std::string& key) {
  Statement s = db.prepare(select);
  s.bind(1, key);
  if (s.step()) return s.columnInt(0);
  Statement i = db.prepare(insert);
  i.bind(1, key);
  i.run();
  return db.lastInsertId();
}

std::optional<double> number(const nlohmann::json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;  // null: not measurable
  return it->get<double>();
}

// A section's value: missing or null is "not measured" (NULL); anything but a
// number refuses the whole import rather than storing NULL for a typo.
std::optional<double> measured(const nlohmann::json& object, const char* key, const std::string& where,
                               const char* function) {
  auto it = object.find(key);
  if (it == object.end() || it->is_null()) return std::nullopt;
  if (!it->is_number())
    throw InvalidInput(std::string("[") + function + "] " + where + ": " + key + " must be a number or null (got " +
                       it->dump() + ")");
  return it->get<double>();
}

void requireFinite(const std::optional<double>& v, const char* name) {
  if (v && !std::isfinite(*v))
    throw InvalidInput(std::string("[importScan] ") + name + " must be finite (got " + std::to_string(*v) + ")");
}

// The sail's lengths and area as the analysis JSON gives them: a number no measured
// sail can have (a cloud scaled by 1e30, a cloud in millimetres) is refused, not stored.
void refuseImplausibleSail(const nlohmann::json& sail, const char* function) {
  if (!sail.is_object()) return;
  for (const char* key : {"luff_length_m", "leech_length_m", "foot_length_m", "top_length_m", "area_m2"}) {
    const std::optional<double> v = measured(sail, key, "sail", function);
    if (!v) continue;
    const bool area = std::string(key) == "area_m2";
    const auto why = area ? implausibleArea(*v, std::string("sail.") + key) : implausibleLength(*v, std::string("sail.") + key);
    if (why) throw InvalidInput(std::string("[") + function + "] " + *why);
  }
}

// Writes the analysis row and its sections; the caller holds the transaction.
int64_t writeAnalysis(Database& db, int64_t scan_id, const nlohmann::json& doc, const std::string& software_version,
                      const std::vector<uint8_t>* surface_blob, const char* function, size_t* sections_written,
                      const ImportHook& hook) {
  Statement a = db.prepare(
      "INSERT INTO analyses(scan_id, software_version, params, sail, diagnostics, surface_mesh) VALUES (?, ?, ?, ?, ?, ?)");
  a.bind(1, scan_id).bind(2, software_version);
  if (surface_blob) a.bindBlob(6, *surface_blob); else a.bindNull(6);
  auto json_or_null = [&](int index, const char* key) {
    if (doc.contains(key)) a.bind(index, doc[key].dump()); else a.bindNull(index);
  };
  json_or_null(3, "parameters");
  nlohmann::json sail = doc.value("sail", nlohmann::json::object());
  refuseImplausibleSail(sail, function);
  if (doc.contains("luff")) sail["luff"] = doc["luff"];
  a.bind(4, sail.dump());
  // Sections asked for but not measured ride in the diagnostics: the sections table
  // holds measured ones only.
  if (doc.contains("unmeasured_sections")) {
    const nlohmann::json& u = doc["unmeasured_sections"];
    if (!u.is_array())
      throw InvalidInput(std::string("[") + function + "] unmeasured_sections must be an array (got " + u.dump() + ")");
    for (const nlohmann::json& x : u) {
      const auto fraction = x.is_object() ? number(x, "fraction") : std::nullopt;
      if (!fraction || *fraction <= 0 || *fraction >= 1 || !x.contains("reason") || !x["reason"].is_string())
        throw InvalidInput(std::string("[") + function +
                           "] an unmeasured section needs a fraction in (0, 1) and a reason (got " + x.dump() + ")");
      for (const nlohmann::json& j : doc["sections"]) {
        const auto measured = number(j, "fraction");
        if (measured && std::abs(*measured - *fraction) < 1e-9)
          throw InvalidInput(std::string("[") + function + "] section " + std::to_string(*fraction) +
                             " is both measured and unmeasured");
      }
    }
    nlohmann::json diagnostics = doc.value("diagnostics", nlohmann::json::object());  // an object: checked by the callers
    diagnostics["unmeasured_sections"] = u;
    a.bind(5, diagnostics.dump());
  } else {
    json_or_null(5, "diagnostics");
  }
  a.run();
  const int64_t analysis_id = db.lastInsertId();
  if (hook) hook("analysis");

  Statement sec = db.prepare(
      "INSERT INTO sections(analysis_id, fraction, chord_m, camber_pct, draft_pct, twist_deg, twist_rel_deg, entry_deg,"
      " exit_deg, u_chord_m, u_camber_pct, u_draft_pct, u_twist_deg, u_twist_rel_deg, u_entry_deg, u_exit_deg,"
      " plane_tilt_deg, converged, curve) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const nlohmann::json& j : doc["sections"]) {
    const auto fraction = number(j, "fraction");
    if (!fraction || *fraction <= 0 || *fraction >= 1)
      throw InvalidInput(std::string("[") + function + "] section fraction must be in (0, 1) (got " +
                         j.value("fraction", nlohmann::json()).dump() + ")");
    sec.bind(1, analysis_id).bind(2, *fraction);
    const std::string where = "section " + formatFixed(*fraction);
    nlohmann::json u = nlohmann::json::object();
    if (j.contains("uncertainty") && !j["uncertainty"].is_null()) {
      u = j["uncertainty"];
      if (!u.is_object())
        throw InvalidInput(std::string("[") + function + "] " + where + ": uncertainty must be an object (got " + u.dump() + ")");
    }
    for (int k = 0; k < 7; ++k) {
      sec.bind(3 + k, measured(j, kParameters[k], where, function));
      sec.bind(10 + k, measured(u, kParameters[k], where + " uncertainty", function));
    }
    sec.bind(17, measured(j, "plane_tilt_deg", where, function));
    nlohmann::json converged = j.value("converged", nlohmann::json(true));
    if (converged.is_null()) converged = true;
    if (!converged.is_boolean())
      throw InvalidInput(std::string("[") + function + "] " + where + ": converged must be true or false (got " +
                         converged.dump() + ")");
    sec.bind(18, converged.get<bool>() ? 1 : 0);
    std::vector<Vec3> curve;
    if (j.contains("curve"))
      for (const auto& p : j["curve"]) curve.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
    sec.bindBlob(19, packCurve(curve));
    sec.run();
    sec.reset();
    if (sections_written) ++*sections_written;
  }
  return analysis_id;
}

// Every row of one import; the caller holds the transaction.
void writeImport(Database& db, const ImportMetadata& meta, const nlohmann::json* analysis, const Cloud* cloud,
                 const std::vector<uint8_t>* cloud_blob, const std::vector<uint8_t>* surface_blob,
                 const ImportHook& hook, ImportResult& result) {
  Statement c = db.prepare("SELECT id FROM campaigns WHERE name = ?");
  c.bind(1, meta.campaign);
  int64_t campaign_id;
  if (c.step()) {
    campaign_id = c.columnInt(0);
  } else {
    Statement i = db.prepare("INSERT INTO campaigns(name, kind) VALUES (?, ?)");
    i.bind(1, meta.campaign).bind(2, meta.campaign_kind).run();
    campaign_id = db.lastInsertId();
  }

  Statement se = db.prepare("SELECT id FROM sessions WHERE campaign_id = ? AND name = ?");
  se.bind(1, campaign_id).bind(2, meta.session);
  int64_t session_id;
  if (se.step()) {
    session_id = se.columnInt(0);
  } else {
    Statement i = db.prepare("INSERT INTO sessions(campaign_id, name, started_at) VALUES (?, ?, ?)");
    i.bind(1, campaign_id).bind(2, meta.session);
    if (meta.scanned_at.empty()) i.bindNull(3); else i.bind(3, meta.scanned_at);
    i.run();
    session_id = db.lastInsertId();
  }

  std::optional<int64_t> boat_id;
  if (!meta.boat.empty())
    boat_id = findOrCreate(db, "SELECT id FROM boats WHERE name = ?", "INSERT INTO boats(name) VALUES (?)", meta.boat);
  const int64_t sail_id =
      findOrCreate(db, "SELECT id FROM sails WHERE name = ?", "INSERT INTO sails(name) VALUES (?)", meta.sail);
  // Written only when it changes: concurrent importers of one sail then do not
  // all write its row (on PostgreSQL each such write would abort the others).
  if (!meta.sail_type.empty())
    db.prepare("UPDATE sails SET type = ? WHERE id = ? AND (type IS NULL OR type <> ?)")
        .bind(1, meta.sail_type).bind(2, sail_id).bind(3, meta.sail_type).run();
  if (boat_id)
    db.prepare("UPDATE sails SET boat_id = ? WHERE id = ? AND (boat_id IS NULL OR boat_id <> ?)")
        .bind(1, *boat_id).bind(2, sail_id).bind(3, *boat_id).run();

  std::optional<int64_t> unit_id;
  if (!meta.scanner_unit.empty())
    unit_id = findOrCreate(db, "SELECT id FROM scanner_units WHERE serial = ?",
                           "INSERT INTO scanner_units(serial) VALUES (?)", meta.scanner_unit);

  // The trim step: one per (session, sail, test, order); later imports of the
  // same step add scans and update the values they carry.
  Statement t = db.prepare("SELECT id FROM trim_steps WHERE session_id = ? AND sail_id = ? AND test = ? AND step_order = ?");
  t.bind(1, session_id).bind(2, sail_id).bind(3, meta.test).bind(4, meta.trim_step);
  if (t.step()) {
    result.trim_step_id = t.columnInt(0);
    Statement u = db.prepare(
        "UPDATE trim_steps SET awa_deg = coalesce(?, awa_deg), aws_m_s = coalesce(?, aws_m_s), drive_n = coalesce(?, drive_n),"
        " side_n = coalesce(?, side_n), heel_moment_nm = coalesce(?, heel_moment_nm) WHERE id = ?");
    u.bind(1, meta.awa_deg).bind(2, meta.aws_m_s).bind(3, meta.drive_n).bind(4, meta.side_n).bind(5, meta.heel_moment_nm);
    u.bind(6, result.trim_step_id).run();
  } else {
    Statement i = db.prepare(
        "INSERT INTO trim_steps(session_id, sail_id, test, step_order, awa_deg, aws_m_s, drive_n, side_n, heel_moment_nm)"
        " VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    i.bind(1, session_id).bind(2, sail_id).bind(3, meta.test).bind(4, meta.trim_step).bind(5, meta.awa_deg);
    i.bind(6, meta.aws_m_s).bind(7, meta.drive_n).bind(8, meta.side_n).bind(9, meta.heel_moment_nm).run();
    result.trim_step_id = db.lastInsertId();
  }
  Statement cs = db.prepare("INSERT INTO control_settings(trim_step_id, name, value) VALUES (?, ?, ?)"
                            " ON CONFLICT (trim_step_id, name) DO UPDATE SET value = excluded.value");
  for (const auto& [name, value] : meta.controls) {
    cs.bind(1, result.trim_step_id).bind(2, name).bind(3, value).run();
    cs.reset();
  }
  Statement pr = db.prepare("INSERT INTO pressures(trim_step_id, tap, pressure_pa) VALUES (?, ?, ?)"
                            " ON CONFLICT (trim_step_id, tap) DO UPDATE SET pressure_pa = excluded.pressure_pa");
  for (const auto& [tap, value] : meta.pressures_pa) {
    pr.bind(1, result.trim_step_id).bind(2, tap).bind(3, value).run();
    pr.reset();
  }

  size_t point_count = cloud ? cloud->size() : 0;
  if (!cloud && analysis) {
    const auto& d = analysis->value("diagnostics", nlohmann::json::object());
    point_count = d.value("points_in", size_t{0});
  }
  Statement s = db.prepare(
      "INSERT INTO scans(trim_step_id, unit_id, scanned_at, settings, raw_capture, cloud, point_count, region)"
      " VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
  if (meta.region) s.bind(8, regionToJson(*meta.region).dump()); else s.bindNull(8);
  s.bind(1, result.trim_step_id);
  if (unit_id) s.bind(2, *unit_id); else s.bindNull(2);
  if (meta.scanned_at.empty()) s.bindNull(3); else s.bind(3, meta.scanned_at);
  if (meta.settings.is_null()) s.bindNull(4); else s.bind(4, meta.settings.dump());
  if (meta.raw_capture.empty()) s.bindNull(5); else s.bind(5, meta.raw_capture);
  if (cloud_blob) s.bindBlob(6, *cloud_blob); else s.bindNull(6);
  s.bind(7, static_cast<int64_t>(point_count)).run();
  result.scan_id = db.lastInsertId();
  if (hook) hook("scan");

  if (analysis) {
    result.analysis_id =
        writeAnalysis(db, result.scan_id, *analysis, meta.software_version, surface_blob, "importScan",
                      &result.sections, hook);
    if (hook) hook("sections");
    if (meta.design_comparison)
      addDesignComparison(db, result.analysis_id, meta.sail, meta.design_comparison->stats, meta.design_comparison->details);
  }
}


bool hasSectionsArray(const nlohmann::json& doc) {
  return doc.is_object() && doc.contains("sections") && doc["sections"].is_array();
}

// The analysis's surface as stored; none for a missing or empty mesh.
std::optional<std::vector<uint8_t>> surfaceBlob(const Mesh* surface) {
  if (!surface || surface->empty()) return std::nullopt;
  return packMesh(*surface);
}

}  // namespace

std::vector<uint8_t> packCurve(const std::vector<Vec3>& curve) {
  std::vector<uint8_t> out(curve.size() * 24);
  for (size_t i = 0; i < curve.size(); ++i) std::memcpy(out.data() + 24 * i, curve[i].data(), 24);
  return out;
}

std::vector<Vec3> unpackCurve(const std::vector<uint8_t>& blob) {
  if (blob.size() % 24 != 0)
    throw DatabaseError("[unpackCurve] curve blob of " + std::to_string(blob.size()) + " bytes is not N×3 float64");
  std::vector<Vec3> curve(blob.size() / 24);
  for (size_t i = 0; i < curve.size(); ++i) std::memcpy(curve[i].data(), blob.data() + 24 * i, 24);
  return curve;
}


ImportResult importScan(Database& db, const ImportMetadata& meta, const nlohmann::json* analysis, const Cloud* cloud,
                        const ImportHook& hook, const Mesh* surface) {
  if (meta.campaign.empty()) throw InvalidInput("[importScan] campaign name must not be empty");
  if (meta.sail.empty()) throw InvalidInput("[importScan] sail name must not be empty");
  if (meta.campaign_kind != "full_scale" && meta.campaign_kind != "wind_tunnel")
    throw InvalidInput("[importScan] campaign_kind must be full_scale or wind_tunnel (got \"" + meta.campaign_kind + "\")");
  requireFinite(meta.awa_deg, "awa_deg");
  requireFinite(meta.aws_m_s, "aws_m_s");
  if (meta.awa_deg && (*meta.awa_deg < -180 || *meta.awa_deg > 360))
    throw InvalidInput("[importScan] awa_deg must be in [-180, 360] (got " + std::to_string(*meta.awa_deg) + ")");
  if (!analysis && !cloud) throw InvalidInput("[importScan] nothing to import: neither an analysis nor a cloud");
  if (analysis && !hasSectionsArray(*analysis))
    throw InvalidInput("[importScan] the analysis document has no \"sections\" array (is it `sailshape analyze --json` output?)");
  if (analysis && analysis->contains("diagnostics") && !(*analysis)["diagnostics"].is_object())
    throw InvalidInput("[importScan] the analysis document's diagnostics must be an object (got " +
                       std::string((*analysis)["diagnostics"].type_name()) + ")");
  for (const auto& [name, value] : meta.controls)
    if (name.empty() || !std::isfinite(value))
      throw InvalidInput("[importScan] control setting \"" + name + "\" needs a name and a finite value (got " +
                         std::to_string(value) + ")");

  // Compressed before the transaction: it is the import's longest step, and the
  // write lock (SQLite) or a retry (PostgreSQL) need not wait for it again.
  const std::optional<std::vector<uint8_t>> cloud_blob =
      cloud ? std::optional<std::vector<uint8_t>>(compressCloud(*cloud)) : std::nullopt;
  const std::optional<std::vector<uint8_t>> surface_blob = analysis ? surfaceBlob(surface) : std::nullopt;
  ImportResult result;
  runTransaction(db, [&] {
    result = ImportResult{};
    writeImport(db, meta, analysis, cloud, cloud_blob ? &*cloud_blob : nullptr, surface_blob ? &*surface_blob : nullptr,
                hook, result);
  });
  return result;
}


int64_t addAnalysis(Database& db, int64_t scan_id, const nlohmann::json& analysis, const std::string& software_version,
                    const Mesh* surface) {
  if (!hasSectionsArray(analysis))
    throw InvalidInput("[addAnalysis] the analysis document has no \"sections\" array");
  if (analysis.contains("diagnostics") && !analysis["diagnostics"].is_object())
    throw InvalidInput("[addAnalysis] the analysis document's diagnostics must be an object (got " +
                       std::string(analysis["diagnostics"].type_name()) + ")");
  const std::optional<std::vector<uint8_t>> surface_blob = surfaceBlob(surface);
  int64_t id = 0;
  runTransaction(db, [&] {
    Statement s = db.prepare("SELECT 1 FROM scans WHERE id = ?");
    s.bind(1, scan_id);
    if (!s.step()) throw InvalidInput("[addAnalysis] no scan with id " + std::to_string(scan_id));
    id = writeAnalysis(db, scan_id, analysis, software_version, surface_blob ? &*surface_blob : nullptr, "addAnalysis",
                       nullptr, {});
  });
  return id;
}

}  // namespace sailshape
