#include "database/schema.hpp"

#include "database/dialect.hpp"

namespace sailshape {
namespace {

// Each entry takes the schema from version i to i + 1. Never edit a shipped
// step: add a new one, so every existing file follows the same path.
const char* const kMigrations[kSchemaVersion] = {
    // 1: the store.
    R"sql(
CREATE TABLE campaigns (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  kind TEXT NOT NULL DEFAULT 'full_scale' CHECK (kind IN ('wind_tunnel', 'full_scale')),
  place TEXT, start_date TEXT, end_date TEXT, notes TEXT);
CREATE TABLE boats (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  class TEXT, notes TEXT);
CREATE TABLE sails (
  id INTEGER PRIMARY KEY,
  boat_id INTEGER REFERENCES boats(id) ON DELETE SET NULL,
  name TEXT NOT NULL UNIQUE,
  type TEXT,                -- mainsail, genoa, gennaker, spinnaker, ...
  size_variant TEXT, designer TEXT, version TEXT,
  design_mesh BLOB,         -- the design surface, database/catalog.hpp packMesh
  design_params TEXT);      -- JSON
CREATE TABLE scanner_units (
  id INTEGER PRIMARY KEY,
  serial TEXT NOT NULL UNIQUE,
  model TEXT, notes TEXT);
CREATE TABLE calibrations (
  id INTEGER PRIMARY KEY,
  unit_id INTEGER NOT NULL REFERENCES scanner_units(id) ON DELETE CASCADE,
  calibrated_at TEXT NOT NULL,
  p_m REAL NOT NULL,        -- mirror-to-turntable-axis offset (SPEC §2)
  theta_deg REAL NOT NULL,  -- scan plane tilt (SPEC §2)
  notes TEXT);
CREATE TABLE sessions (
  id INTEGER PRIMARY KEY,
  campaign_id INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  started_at TEXT, notes TEXT,
  UNIQUE (campaign_id, name));
CREATE TABLE trim_steps (
  id INTEGER PRIMARY KEY,
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  sail_id INTEGER NOT NULL REFERENCES sails(id),
  test TEXT NOT NULL DEFAULT '',
  step_order INTEGER NOT NULL,
  awa_deg REAL, aws_m_s REAL,
  drive_n REAL, side_n REAL, heel_moment_nm REAL,
  UNIQUE (session_id, sail_id, test, step_order));
CREATE TABLE control_settings (
  trim_step_id INTEGER NOT NULL REFERENCES trim_steps(id) ON DELETE CASCADE,
  name TEXT NOT NULL,       -- tack_height, sheet, traveller, halyard, ...
  value REAL NOT NULL,
  PRIMARY KEY (trim_step_id, name)) WITHOUT ROWID;
CREATE TABLE pressures (
  trim_step_id INTEGER NOT NULL REFERENCES trim_steps(id) ON DELETE CASCADE,
  tap TEXT NOT NULL,
  pressure_pa REAL NOT NULL,
  PRIMARY KEY (trim_step_id, tap)) WITHOUT ROWID;
CREATE TABLE scans (
  id INTEGER PRIMARY KEY,
  trim_step_id INTEGER REFERENCES trim_steps(id) ON DELETE CASCADE,
  unit_id INTEGER REFERENCES scanner_units(id),
  scanned_at TEXT,
  settings TEXT,            -- acquisition settings, JSON
  raw_capture TEXT,         -- path or URI of the raw scanner capture
  cloud BLOB,               -- database/cloud_blob.hpp
  point_count INTEGER NOT NULL DEFAULT 0);
CREATE TABLE registrations (
  id INTEGER PRIMARY KEY,
  scan_id INTEGER NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
  transform TEXT NOT NULL,  -- JSON 4×4 row-major, scanner to boat frame
  fitness REAL, rmse_m REAL);
CREATE TABLE analyses (
  id INTEGER PRIMARY KEY,
  scan_id INTEGER NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
  software_version TEXT NOT NULL,
  created_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ', 'now')),
  params TEXT,              -- pipeline parameters, JSON
  sail TEXT,                -- outline and luff curve, JSON
  diagnostics TEXT);        -- stage timings, clusters, smoothing, warnings, JSON
CREATE TABLE sections (
  id INTEGER PRIMARY KEY,
  analysis_id INTEGER NOT NULL REFERENCES analyses(id) ON DELETE CASCADE,
  fraction REAL NOT NULL,
  chord_m REAL, camber_pct REAL, draft_pct REAL, twist_deg REAL, twist_rel_deg REAL, entry_deg REAL, exit_deg REAL,
  u_chord_m REAL, u_camber_pct REAL, u_draft_pct REAL, u_twist_deg REAL, u_twist_rel_deg REAL, u_entry_deg REAL,
  u_exit_deg REAL,          -- 1σ uncertainties, same units
  plane_tilt_deg REAL,
  converged INTEGER NOT NULL DEFAULT 1,
  curve BLOB);              -- N×3 float64 little-endian, metres, boat frame, luff to leech
)sql",
    // 2: design-vs-flying statistics.
    R"sql(
CREATE TABLE design_comparisons (
  id INTEGER PRIMARY KEY,
  analysis_id INTEGER NOT NULL REFERENCES analyses(id) ON DELETE CASCADE,
  sail_id INTEGER NOT NULL REFERENCES sails(id),
  mean_m REAL, rms_m REAL, max_abs_m REAL,  -- signed distance flying to design
  stats TEXT);                               -- full comparison, JSON
)sql",
    // 3: indices for the reference-database queries.
    R"sql(
CREATE INDEX sails_boat ON sails(boat_id);
CREATE INDEX sails_type ON sails(type);
CREATE INDEX sessions_campaign ON sessions(campaign_id);
CREATE INDEX trim_steps_sail_awa ON trim_steps(sail_id, awa_deg);
CREATE INDEX trim_steps_awa ON trim_steps(awa_deg);
CREATE INDEX trim_steps_test ON trim_steps(session_id, test, step_order);
CREATE INDEX control_settings_name ON control_settings(name, value);
CREATE INDEX scans_trim_step ON scans(trim_step_id);
CREATE INDEX registrations_scan ON registrations(scan_id);
CREATE INDEX calibrations_unit ON calibrations(unit_id, calibrated_at);
CREATE INDEX analyses_scan ON analyses(scan_id);
CREATE INDEX sections_analysis ON sections(analysis_id, fraction);
CREATE INDEX design_comparisons_analysis ON design_comparisons(analysis_id);
)sql",
    // 4: the surface the analysis reconstructed, so a report draws the sail that was scanned.
    R"sql(
ALTER TABLE analyses ADD COLUMN surface_mesh BLOB;  -- catalog.hpp packMesh: metres, boat frame; NULL: not stored
)sql",
    // 5: design versions per sail, and the region a scan's sail lies in. A sail's
    // stored design becomes its version 1; sails.design_mesh and design_params keep
    // a copy of the current (highest) version for readers of the sail row.
    R"sql(
CREATE TABLE design_versions (
  id INTEGER PRIMARY KEY,
  sail_id INTEGER NOT NULL REFERENCES sails(id) ON DELETE CASCADE,
  version INTEGER NOT NULL,
  added_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%SZ', 'now')),
  source TEXT,              -- the file it was read from
  format TEXT, unit TEXT, axes TEXT,  -- as analysis/io/design_import.hpp applied them
  mesh BLOB NOT NULL,       -- database/catalog.hpp packMesh, metres, boat frame
  params TEXT,              -- JSON
  UNIQUE (sail_id, version));
INSERT INTO design_versions(sail_id, version, source, mesh, params)
  SELECT id, 1, 'stored with the sail', design_mesh, design_params FROM sails WHERE design_mesh IS NOT NULL;
ALTER TABLE scans ADD COLUMN region TEXT;  -- JSON {"box_m": [xmin, xmax, ymin, ymax, zmin, zmax], "design_version": n}
)sql",
};

}  // namespace

namespace {

// Holds the schema lock of a PostgreSQL store while migrations run, so two
// processes opening a new store migrate it once.
class SchemaLock {
 public:
  explicit SchemaLock(Database& db) : db_(db) { db_.lockSchema(true); }
  ~SchemaLock() {
    try {
      db_.lockSchema(false);
    } catch (const DatabaseError&) {
      // A lost connection released the lock with the session.
    }
  }
  SchemaLock(const SchemaLock&) = delete;
  SchemaLock& operator=(const SchemaLock&) = delete;

 private:
  Database& db_;
};

}  // namespace

void migrateSchema(Database& db, int target_version) {
  const int current = db.userVersion();
  if (current > kSchemaVersion)
    throw DatabaseError("[migrateSchema] " + db.path() + ": database schema version " + std::to_string(current) +
                        " is newer than this sailshape (" + std::to_string(kSchemaVersion) + ")");
  if (target_version < current || target_version > kSchemaVersion)
    throw DatabaseError("[migrateSchema] target_version must be in [" + std::to_string(current) + ", " +
                        std::to_string(kSchemaVersion) + "] (got " + std::to_string(target_version) + ")");
  SchemaLock lock(db);
  for (int v = current; v < target_version; ++v) {
    Transaction tx(db);
    // Re-read under the write lock: another process may have migrated meanwhile.
    if (db.userVersion() != v) continue;
    db.exec(db.backend() == Backend::PostgreSQL ? detail::postgresDdl(kMigrations[v]) : std::string(kMigrations[v]));
    db.setUserVersion(v + 1);
    tx.commit();
  }
}

Database openSailDatabase(const std::string& path, const OpenOptions& options) {
  Database db(path, options);
  // Version and table count from one snapshot: another opener may be migrating,
  // and tables read after a version of 0 may be its, not a foreign application's.
  db.beginSnapshot();
  int version = 0;
  int64_t tables = 0;
  try {
    version = db.userVersion();
    tables = db.tableCount();
    db.commit();
  } catch (...) {
    db.rollback();
    throw;
  }
  if (version > kSchemaVersion)
    throw DatabaseError("[openSailDatabase] " + db.path() + ": database schema version " + std::to_string(version) +
                        " is newer than this sailshape (" + std::to_string(kSchemaVersion) + ")");
  if (version == 0 && tables > 0)
    throw DatabaseError("[openSailDatabase] " + db.path() + ": " +
                        (db.backend() == Backend::SQLite ? "an SQLite database" : "a PostgreSQL database") +
                        " of another application (tables but no sailshape schema); left untouched");
  // Readers (the viewer) keep reading while a scan is written.
  db.enableConcurrentReaders();
  if (version < kSchemaVersion) {
    if (db.readOnly())
      throw DatabaseError("[openSailDatabase] " + db.path() + ": schema version " + std::to_string(version) +
                          " needs a migration; open it writable (" +
                          (db.backend() == Backend::SQLite ? "the file or its folder is read-only here" : "it was opened read-only") + ")");
    migrateSchema(db);
  }
  return db;
}

}  // namespace sailshape
