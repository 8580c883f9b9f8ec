#include "database/catalog.hpp"

#include <cstring>

#include <nlohmann/json.hpp>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

int64_t sailId(Database& db, const std::string& sail, const char* function) {
  Statement s = db.prepare("SELECT id FROM sails WHERE name = ?");
  s.bind(1, sail);
  if (!s.step()) throw InvalidInput(std::string("[") + function + "] no sail named \"" + sail + "\"");
  return s.columnInt(0);
}

int64_t unitId(Database& db, const std::string& serial) {
  db.prepare("INSERT INTO scanner_units(serial) VALUES (?) ON CONFLICT DO NOTHING").bind(1, serial).run();
  Statement s = db.prepare("SELECT id FROM scanner_units WHERE serial = ?");
  s.bind(1, serial).step();
  return s.columnInt(0);
}

void setIfGiven(Database& db, const char* column, const std::string& value, int64_t id) {
  if (!value.empty())
    db.prepare(std::string("UPDATE sails SET ") + column + " = ? WHERE id = ?").bind(1, value).bind(2, id).run();
}

void checkDesignMesh(const Mesh& mesh) {
  if (mesh.vertices.empty() || mesh.triangles.empty())
    throw InvalidInput("[addDesignVersion] the design has no triangles (" + std::to_string(mesh.vertices.size()) +
                       " vertices, " + std::to_string(mesh.triangles.size()) + " triangles)");
  for (const Vec3& v : mesh.vertices)
    if (!v.allFinite()) throw InvalidInput("[addDesignVersion] the design has a vertex that is not a finite number");
}

bool sameAsCurrentDesign(Database& db, int64_t sail_id, const Mesh& mesh) {
  Statement s = db.prepare("SELECT mesh FROM design_versions WHERE sail_id = ? ORDER BY version DESC LIMIT 1");
  s.bind(1, sail_id);
  return s.step() && s.columnBlob(0) == packMesh(mesh);
}

// The sail's next design version, and the copy of it in the sail's row; inside the caller's transaction.
int storeDesignVersion(Database& db, int64_t sail_id, const Mesh& mesh, const DesignSource& source,
                       const nlohmann::json* params) {
  checkDesignMesh(mesh);
  Statement last = db.prepare("SELECT coalesce(max(version), 0) FROM design_versions WHERE sail_id = ?");
  last.bind(1, sail_id).step();
  const int version = static_cast<int>(last.columnInt(0)) + 1;
  const std::vector<uint8_t> blob = packMesh(mesh);
  Statement s = db.prepare(
      "INSERT INTO design_versions(sail_id, version, source, format, unit, axes, mesh, params) VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
  s.bind(1, sail_id).bind(2, int64_t{version}).bind(3, source.file).bind(4, source.format).bind(5, source.unit);
  s.bind(6, source.axes).bindBlob(7, blob);
  if (params) s.bind(8, params->dump());
  else s.bindNull(8);
  s.run();
  Statement row = db.prepare("UPDATE sails SET design_mesh = ?, design_params = ? WHERE id = ?");
  row.bindBlob(1, blob);
  if (params) row.bind(2, params->dump());
  else row.bindNull(2);
  row.bind(3, sail_id).run();
  return version;
}

}  // namespace

std::vector<uint8_t> packMesh(const Mesh& mesh) {
  const uint64_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  std::vector<uint8_t> out(4 + 16 + nv * 24 + nt * 12);
  std::memcpy(out.data(), "SSM1", 4);
  std::memcpy(out.data() + 4, &nv, 8);
  std::memcpy(out.data() + 12, &nt, 8);
  uint8_t* p = out.data() + 20;
  for (const Vec3& v : mesh.vertices) std::memcpy(p, v.data(), 24), p += 24;
  for (const auto& t : mesh.triangles) std::memcpy(p, t.data(), 12), p += 12;
  return out;
}

Mesh unpackMesh(const std::vector<uint8_t>& blob) {
  uint64_t nv = 0, nt = 0;
  if (blob.size() < 20 || std::memcmp(blob.data(), "SSM1", 4) != 0)
    throw DatabaseError("[unpackMesh] not a sailshape mesh blob (" + std::to_string(blob.size()) + " bytes)");
  std::memcpy(&nv, blob.data() + 4, 8);
  std::memcpy(&nt, blob.data() + 12, 8);
  if (nv > blob.size() || nt > blob.size() || blob.size() != 20 + nv * 24 + nt * 12)
    throw DatabaseError("[unpackMesh] " + std::to_string(nv) + " vertices and " + std::to_string(nt) +
                        " triangles do not fit " + std::to_string(blob.size()) + " bytes");
  Mesh mesh;
  mesh.vertices.resize(nv);
  mesh.triangles.resize(nt);
  const uint8_t* p = blob.data() + 20;
  for (auto& v : mesh.vertices) std::memcpy(v.data(), p, 24), p += 24;
  for (auto& t : mesh.triangles) {
    std::memcpy(t.data(), p, 12), p += 12;
    for (uint32_t i : t)
      if (i >= nv) throw DatabaseError("[unpackMesh] triangle index " + std::to_string(i) + " >= " + std::to_string(nv));
  }
  return mesh;
}

int64_t upsertSail(Database& db, const SailInfo& info, const Mesh* design_mesh, const nlohmann::json* design_params) {
  if (info.name.empty()) throw InvalidInput("[upsertSail] sail name must not be empty");
  int64_t id = 0;
  runTransaction(db, [&] {
    db.prepare("INSERT INTO sails(name) VALUES (?) ON CONFLICT DO NOTHING").bind(1, info.name).run();
    id = sailId(db, info.name, "upsertSail");
    setIfGiven(db, "type", info.type, id);
    setIfGiven(db, "size_variant", info.size_variant, id);
    setIfGiven(db, "designer", info.designer, id);
    setIfGiven(db, "version", info.version, id);
    if (!info.boat.empty()) {
      db.prepare("INSERT INTO boats(name) VALUES (?) ON CONFLICT DO NOTHING").bind(1, info.boat).run();
      db.prepare("UPDATE sails SET boat_id = (SELECT id FROM boats WHERE name = ?) WHERE id = ?").bind(1, info.boat).bind(2, id).run();
    }
    // The same design stored again (the demo stores its designs at every run) is not a new version.
    if (design_mesh && !sameAsCurrentDesign(db, id, *design_mesh)) storeDesignVersion(db, id, *design_mesh, {}, design_params);
    else if (design_params) db.prepare("UPDATE sails SET design_params = ? WHERE id = ?").bind(1, design_params->dump()).bind(2, id).run();
  });
  return id;
}

int addDesignVersion(Database& db, const std::string& sail, const Mesh& mesh, const DesignSource& source,
                     const nlohmann::json* params) {
  if (sail.empty()) throw InvalidInput("[addDesignVersion] sail name must not be empty");
  int version = 0;
  runTransaction(db, [&] {
    db.prepare("INSERT INTO sails(name) VALUES (?) ON CONFLICT DO NOTHING").bind(1, sail).run();
    version = storeDesignVersion(db, sailId(db, sail, "addDesignVersion"), mesh, source, params);
  });
  return version;
}

std::vector<DesignVersion> designVersions(Database& db, const std::string& sail) {
  const int64_t id = sailId(db, sail, "designVersions");
  Statement s = db.prepare(
      "SELECT version, added_at, source, format, unit, axes, mesh FROM design_versions WHERE sail_id = ? ORDER BY version");
  s.bind(1, id);
  std::vector<DesignVersion> out;
  while (s.step()) {
    DesignVersion v;
    v.version = static_cast<int>(s.columnInt(0));
    v.added_at = s.columnText(1);
    v.source = {s.columnText(2), s.columnText(3), s.columnText(4), s.columnText(5)};
    const Mesh m = unpackMesh(s.columnBlob(6));
    v.vertices = m.vertices.size();
    v.triangles = m.triangles.size();
    out.push_back(v);
  }
  if (!out.empty()) out.back().current = true;
  return out;
}

Mesh designVersionMesh(Database& db, const std::string& sail, int version) {
  const int64_t id = sailId(db, sail, "designVersionMesh");
  if (version < 0) throw InvalidInput("[designVersionMesh] design version must be >= 1 (got " + std::to_string(version) + ")");
  Statement s = db.prepare(version == 0
                               ? "SELECT mesh FROM design_versions WHERE sail_id = ? ORDER BY version DESC LIMIT 1"
                               : "SELECT mesh FROM design_versions WHERE sail_id = ? AND version = ?");
  s.bind(1, id);
  if (version) s.bind(2, int64_t{version});
  if (!s.step())
    throw InvalidInput(version == 0 ? "sail \"" + sail + "\" has no design (store one with `sailshape db design add`)"
                                    : "sail \"" + sail + "\" has no design version " + std::to_string(version));
  return unpackMesh(s.columnBlob(0));
}

int currentDesignVersion(Database& db, const std::string& sail) {
  Statement s = db.prepare(
      "SELECT max(v.version) FROM design_versions v JOIN sails s ON s.id = v.sail_id WHERE s.name = ?");
  s.bind(1, sail);
  if (!s.step() || s.isNull(0)) return 0;
  return static_cast<int>(s.columnInt(0));
}

Mesh sailDesignMesh(Database& db, const std::string& sail) {
  Statement s = db.prepare("SELECT design_mesh FROM sails WHERE name = ?");
  s.bind(1, sail);
  if (!s.step()) throw InvalidInput("[sailDesignMesh] no sail named \"" + sail + "\"");
  if (s.isNull(0)) throw InvalidInput("[sailDesignMesh] sail \"" + sail + "\" has no design mesh");
  return unpackMesh(s.columnBlob(0));
}

int64_t addCalibration(Database& db, const std::string& serial, const Calibration& c) {
  if (serial.empty()) throw InvalidInput("[addCalibration] scanner serial must not be empty");
  if (c.calibrated_at.empty()) throw InvalidInput("[addCalibration] calibrated_at must not be empty");
  int64_t id = 0;
  runTransaction(db, [&] {
    const int64_t unit = unitId(db, serial);
    db.prepare("INSERT INTO calibrations(unit_id, calibrated_at, p_m, theta_deg) VALUES (?, ?, ?, ?)")
        .bind(1, unit).bind(2, c.calibrated_at).bind(3, c.p_m).bind(4, c.theta_deg).run();
    id = db.lastInsertId();
  });
  return id;
}

std::optional<Calibration> calibrationAt(Database& db, const std::string& serial, const std::string& at) {
  Statement s = db.prepare(
      "SELECT k.calibrated_at, k.p_m, k.theta_deg FROM calibrations k JOIN scanner_units u ON u.id = k.unit_id"
      " WHERE u.serial = ? AND k.calibrated_at <= ? ORDER BY k.calibrated_at DESC, k.id DESC LIMIT 1");
  s.bind(1, serial).bind(2, at);
  if (!s.step()) return std::nullopt;
  return Calibration{s.columnText(0), s.columnDouble(1), s.columnDouble(2)};
}

int64_t addRegistration(Database& db, int64_t scan_id, const Eigen::Matrix4d& transform, double fitness, double rmse_m) {
  if (!transform.allFinite()) throw InvalidInput("[addRegistration] transform has non-finite entries");
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({transform(r, 0), transform(r, 1), transform(r, 2), transform(r, 3)});
  Statement s = db.prepare("INSERT INTO registrations(scan_id, transform, fitness, rmse_m) VALUES (?, ?, ?, ?)");
  s.bind(1, scan_id).bind(2, rows.dump()).bind(3, fitness).bind(4, rmse_m).run();  // foreign key checks scan_id
  return db.lastInsertId();
}

Eigen::Matrix4d scanTransform(Database& db, int64_t scan_id) {
  Statement s = db.prepare("SELECT transform FROM registrations WHERE scan_id = ? ORDER BY id DESC LIMIT 1");
  s.bind(1, scan_id);
  if (!s.step()) throw InvalidInput("[scanTransform] scan " + std::to_string(scan_id) + " has no registration");
  const nlohmann::json rows = nlohmann::json::parse(s.columnText(0));
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  return m;
}

int64_t addDesignComparison(Database& db, int64_t analysis_id, const std::string& sail, const DistanceStats& stats,
                            const nlohmann::json& details) {
  const int64_t sail_id = sailId(db, sail, "addDesignComparison");
  nlohmann::json all = details;
  all["count"] = stats.count;
  all["p5_m"] = stats.p5_m;
  all["p50_m"] = stats.p50_m;
  all["p95_m"] = stats.p95_m;
  Statement s = db.prepare(
      "INSERT INTO design_comparisons(analysis_id, sail_id, mean_m, rms_m, max_abs_m, stats) VALUES (?, ?, ?, ?, ?, ?)");
  s.bind(1, analysis_id).bind(2, sail_id).bind(3, stats.mean_m).bind(4, stats.rms_m).bind(5, stats.max_abs_m);
  s.bind(6, all.dump()).run();
  return db.lastInsertId();
}

int64_t addDesignComparison(Database& db, int64_t analysis_id, const std::string& sail, const DistanceStats& stats) {
  return addDesignComparison(db, analysis_id, sail, stats, nlohmann::json::object());
}

}  // namespace sailshape
