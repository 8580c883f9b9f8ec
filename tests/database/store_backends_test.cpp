// The store's contract on both backends: schema and migrations, whole-or-absent
// imports, the reference queries, the consistency check, and copies between them.
#include <gtest/gtest.h>

#include <random>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/copy.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "database/table_export.hpp"
#include "store_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::scalar;

class Store : public test::StoreTest {};

// The surface an analysis of the Main reconstructed: two triangles over 2 m × 1 m.
Mesh testSurface() {
  Mesh m;
  m.vertices = {{0, 0, 1}, {2, 0, 1}, {2, 0.1, 2}, {0, 0.1, 2}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

void expectSameMesh(const std::optional<Mesh>& got, const Mesh& want) {
  ASSERT_TRUE(got.has_value());
  ASSERT_EQ(got->vertices.size(), want.vertices.size());
  ASSERT_EQ(got->triangles, want.triangles);
  for (size_t i = 0; i < want.vertices.size(); ++i) EXPECT_EQ(got->vertices[i], want.vertices[i]) << i;
}

// The Queries fixture's data set (queries_test.cpp): Gen-A (genoa, boat Alpha,
// campaign Lorient) test t1 steps 0..3 at AWA 80/90/95/100, drive
// 100/150/130/120 N, side 50/60/40/80 N, sheet 0.1·step, camber at section k
// = 8 + step + k; Gen-B step 0 at AWA 94, drive 140, side 30; Main at AWA 30.
void fill(Database& db) {
  const double awa[] = {80, 90, 95, 100}, drive[] = {100, 150, 130, 120}, side[] = {50, 60, 40, 80};
  for (int step = 0; step < 4; ++step) {
    ImportMetadata m;
    m.campaign = "Lorient";
    m.boat = "Alpha";
    m.sail = "Gen-A";
    m.sail_type = "genoa";
    m.test = "t1";
    m.trim_step = step;
    m.awa_deg = awa[step];
    m.drive_n = drive[step];
    m.side_n = side[step];
    m.controls = {{"sheet", 0.1 * step}, {"traveller", -0.2}};
    m.pressures_pa = {{"p1", 12.5 + step}};
    const nlohmann::json doc = analysisDoc(8.0 + step);
    importScan(db, m, &doc);
  }
  ImportMetadata b;
  b.campaign = "Lorient";
  b.sail = "Gen-B";
  b.sail_type = "genoa";
  b.test = "t2";
  b.awa_deg = 94;
  b.drive_n = 140;
  b.side_n = 30;
  const nlohmann::json doc_b = analysisDoc(20.0);
  importScan(db, b, &doc_b);
  ImportMetadata m;
  m.campaign = "Tunnel";
  m.campaign_kind = "wind_tunnel";
  m.sail = "Main";
  m.sail_type = "mainsail";
  m.awa_deg = 30;
  m.scanner_unit = "LMS511-1";
  const nlohmann::json doc_m = analysisDoc(12.0);
  Cloud cloud;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.004);
  for (int i = 0; i < 2000; ++i) cloud.points.emplace_back(i * 1e-3, noise(rng), 1.0 + noise(rng));
  const Mesh surface = testSurface();
  importScan(db, m, &doc_m, &cloud, {}, &surface);
}

// Every query the CLI offers, as CSV, in one string.
std::string allAnswers(Database& db) {
  std::string out;
  out += tableToCsv(findScans(db));
  out += tableToCsv(findSections(db));
  ScanFilter genoa;
  genoa.sail_type = "genoa";
  genoa.control = "sheet";
  genoa.control_min = 0.1;
  out += tableToCsv(findScans(db, genoa));
  for (const auto& p : sectionParameterNames()) out += tableToCsv(parameterEvolution(db, "t1", p, 0.45));
  out += tableToCsv(compareSails(db, "Gen-A", "Gen-B", 94, 5));
  out += tableToCsv(bestTrimSteps(db, 80, 100, TrimCriterion::Drive, 3));
  out += tableToCsv(bestTrimSteps(db, 80, 100, TrimCriterion::DriveOverSide, 5));
  return out;
}

size_t column(const Table& t, const std::string& name) {
  for (size_t i = 0; i < t.columns.size(); ++i)
    if (t.columns[i] == name) return i;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

TEST_P(Store, NewStoreIsAtTheCurrentVersionAndChecksClean) {
  Database db = openSailDatabase(location_);
  EXPECT_EQ(db.backend(), GetParam());
  EXPECT_EQ(db.userVersion(), kSchemaVersion);
  EXPECT_EQ(db.tableCount(), 15);
  EXPECT_TRUE(db.integrityCheck().empty());
  // Opening again migrates nothing and keeps the version.
  Database again = openSailDatabase(location_);
  EXPECT_EQ(again.userVersion(), kSchemaVersion);
}

TEST_P(Store, MigratesFromEveryOlderVersionKeepingData) {
  for (int from = 0; from < kSchemaVersion; ++from) {
    const std::string location = newLocation();
    {
      Database raw(location);
      migrateSchema(raw, from);
      EXPECT_EQ(raw.userVersion(), from);
      if (from >= 1) raw.exec("INSERT INTO campaigns(name) VALUES ('kept')");
      if (from >= 1) {
        raw.exec("INSERT INTO scans(point_count) VALUES (0)");
        raw.exec("INSERT INTO analyses(scan_id, software_version) VALUES (1, 'old')");
      }
    }
    Database db = openSailDatabase(location);
    EXPECT_EQ(db.userVersion(), kSchemaVersion) << "from " << from;
    EXPECT_EQ(scalar(db, "SELECT count(*) FROM design_comparisons"), 0) << "from " << from;
    if (from >= 1) EXPECT_EQ(scalar(db, "SELECT count(*) FROM campaigns WHERE name = 'kept'"), 1) << "from " << from;
    // Version 4: analyses keep their reconstructed surface; one stored before has none.
    if (from >= 1) {
      EXPECT_EQ(scalar(db, "SELECT count(*) FROM analyses WHERE surface_mesh IS NULL"), 1) << "from " << from;
      EXPECT_FALSE(analysisSurface(db, 1).has_value()) << "from " << from;
    }
    const Mesh surface = testSurface();
    const nlohmann::json doc = analysisDoc(9.0);
    ImportMetadata m;
    const ImportResult r = importScan(db, m, &doc, nullptr, {}, &surface);
    expectSameMesh(analysisSurface(db, r.analysis_id), surface);
    EXPECT_TRUE(db.integrityCheck().empty()) << "from " << from;
  }
}

// A design stored in a sail's row before design versions (schema 3) becomes the
// sail's version 1, byte for byte, and stays its current design; scans keep their rows.
TEST_P(Store, MigrationToDesignVersionsKeepsTheStoredDesignAsVersionOne) {
  Mesh design;
  design.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.2, 0.1, 3)};
  design.triangles = {{0, 1, 2}};
  {
    Database raw(location_);
    migrateSchema(raw, 3);
    raw.prepare("INSERT INTO sails(name, design_mesh, design_params) VALUES ('Old main', ?, '{\"luff_m\": 3}')")
        .bindBlob(1, packMesh(design))
        .run();
    raw.exec("INSERT INTO sails(name) VALUES ('No design')");
    raw.exec("INSERT INTO scans(point_count) VALUES (5)");
  }
  Database db = openSailDatabase(location_);
  EXPECT_EQ(db.userVersion(), kSchemaVersion);
  EXPECT_EQ(currentDesignVersion(db, "Old main"), 1);
  EXPECT_EQ(currentDesignVersion(db, "No design"), 0);
  EXPECT_EQ(packMesh(designVersionMesh(db, "Old main", 1)), packMesh(design));
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM design_versions"), 1);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans WHERE point_count = 5 AND region IS NULL"), 1);
  // A new version becomes current for every reader of the sail row.
  Mesh v2 = design;
  v2.vertices[2].z() = 3.5;
  EXPECT_EQ(addDesignVersion(db, "Old main", v2, {"v2.obj", "obj", "m", "boat"}), 2);
  EXPECT_DOUBLE_EQ(sailDesignMesh(db, "Old main").vertices[2].z(), 3.5);
  EXPECT_DOUBLE_EQ(designVersionMesh(db, "Old main", 1).vertices[2].z(), 3.0);
  const std::vector<DesignVersion> versions = designVersions(db, "Old main");
  ASSERT_EQ(versions.size(), 2u);
  EXPECT_FALSE(versions[0].current);
  EXPECT_TRUE(versions[1].current);
  EXPECT_EQ(versions[1].source.file, "v2.obj");
  EXPECT_TRUE(db.integrityCheck().empty());
}

// A scan's region goes in with the import and comes back with the record.
TEST_P(Store, AScanKeepsItsRegion) {
  Database db = openSailDatabase(location_);
  ImportMetadata m;
  m.sail = "Main";
  m.region = ScanRegion{Eigen::AlignedBox3d(Vec3(-1, -0.5, 0.2), Vec3(0.1, 0.3, 3.2)), 2};
  Cloud cloud;
  cloud.points = {Vec3(0, 0, 1), Vec3(0, 0.1, 1)};
  const ImportResult r = importScan(db, m, nullptr, &cloud);
  const ScanRecord record = loadScanRecord(db, r.scan_id);
  ASSERT_TRUE(record.region.has_value());
  EXPECT_EQ(record.region->design_version, 2);
  EXPECT_TRUE(record.region->box.min().isApprox(Vec3(-1, -0.5, 0.2)));
  EXPECT_TRUE(record.region->box.max().isApprox(Vec3(0.1, 0.3, 3.2)));
  m.region.reset();
  m.trim_step = 1;
  EXPECT_FALSE(loadScanRecord(db, importScan(db, m, nullptr, &cloud).scan_id).region.has_value());
}

TEST_P(Store, NewerSchemaAndForeignTablesAreRefusedAndLeftAsTheyWere) {
  {
    Database raw(location_);
    raw.exec("CREATE TABLE orders (id INTEGER NOT NULL, item TEXT)");
    raw.exec("INSERT INTO orders(id, item) VALUES (1, 'rope')");
  }
  try {
    openSailDatabase(location_);
    ADD_FAILURE() << "a database of another application was opened";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("of another application"), std::string::npos) << e.what();
  }
  Database raw(location_);
  EXPECT_EQ(scalar(raw, "SELECT count(*) FROM orders"), 1);
  EXPECT_EQ(raw.userVersion(), 0);

  const std::string newer = newLocation();
  {
    Database db = openSailDatabase(newer);
    db.setUserVersion(kSchemaVersion + 1);
  }
  EXPECT_THROW(openSailDatabase(newer), DatabaseError);
  EXPECT_EQ(Database(newer).userVersion(), kSchemaVersion + 1);
}

TEST_P(Store, ImportStoresScanAnalysisAndCloudAndReadsThemBack) {
  Database db = openSailDatabase(location_);
  fill(db);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans"), 6);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM sections"), 18);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM trim_steps"), 6);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM control_settings"), 8);
  const int64_t main_scan = scalar(db, "SELECT max(id) FROM scans");
  const ScanRecord r = loadScanRecord(db, main_scan);
  ASSERT_TRUE(r.cloud.has_value());
  ASSERT_EQ(r.cloud->size(), 2000u);
  // float32 storage: ≈ 1e-7 relative, far below the sensor's 4 mm σ.
  EXPECT_NEAR(r.cloud->points[1234].x(), 1.234, 1e-6);
  ASSERT_EQ(r.sections.sections.size(), 3u);
  EXPECT_DOUBLE_EQ(r.sections.sections[1].fraction, 0.5);
  EXPECT_DOUBLE_EQ(r.sections.sections[1].value.camber_pct, 13.0);
  EXPECT_TRUE(std::isnan(r.sections.sections[1].value.exit_deg));
  ASSERT_EQ(r.sections.sections[2].curve.size(), 3u);
  EXPECT_DOUBLE_EQ(r.sections.sections[2].curve[1].y(), 0.1);
  EXPECT_EQ(r.campaign, "Tunnel");
  EXPECT_EQ(r.analysis_params["sensor_sigma_m"].get<double>(), 0.004);
  EXPECT_TRUE(db.integrityCheck().empty());
}

// The surface the analysis reconstructed is stored with it, by an import and by a later
// analysis of the same scan; an analysis stored from its JSON alone has none.
TEST_P(Store, AnAnalysisKeepsTheSurfaceItReconstructed) {
  Database db = openSailDatabase(location_);
  const Mesh surface = testSurface();
  const nlohmann::json doc = analysisDoc(9.0);
  ImportMetadata m;
  const ImportResult with = importScan(db, m, &doc, nullptr, {}, &surface);
  expectSameMesh(analysisSurface(db, with.analysis_id), surface);
  const ImportResult without = importScan(db, m, &doc);
  EXPECT_FALSE(analysisSurface(db, without.analysis_id).has_value());
  Mesh moved = surface;
  for (Vec3& v : moved.vertices) v.z() += 0.5;
  const int64_t again = addAnalysis(db, without.scan_id, doc, "0.1.0", &moved);
  expectSameMesh(analysisSurface(db, again), moved);
  EXPECT_FALSE(analysisSurface(db, addAnalysis(db, without.scan_id, doc)).has_value());
  // An empty mesh is no surface.
  const Mesh empty;
  EXPECT_FALSE(analysisSurface(db, importScan(db, m, &doc, nullptr, {}, &empty).analysis_id).has_value());
}

TEST_P(Store, AFailedImportStoresNothing) {
  Database db = openSailDatabase(location_);
  ImportMetadata m;
  m.campaign = "Lorient";
  m.sail = "Gen-A";
  m.test = "t1";
  m.controls = {{"sheet", 0.3}};
  const nlohmann::json doc = analysisDoc(8.0);
  // Fails after every row was written, before the commit.
  EXPECT_THROW(importScan(db, m, &doc, nullptr,
                          [](const std::string& stage) {
                            if (stage == "sections") throw InvalidInput("[test] stop before commit");
                          }),
               InvalidInput);
  nlohmann::json bad = analysisDoc(8.0);
  bad["sections"][2]["fraction"] = 1.5;  // refused at the third section, two already written
  EXPECT_THROW(importScan(db, m, &bad), InvalidInput);
  for (const char* table : {"campaigns", "sails", "trim_steps", "control_settings", "scans", "analyses", "sections"})
    EXPECT_EQ(scalar(db, std::string("SELECT count(*) FROM ") + table), 0) << table;
  EXPECT_EQ(importScan(db, m, &doc).sections, 3u);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM sections"), 3);
}

TEST_P(Store, QueriesAnswerTheKnownValues) {
  Database db = openSailDatabase(location_);
  fill(db);
  EXPECT_EQ(findScans(db).rows.size(), 6u);
  ScanFilter f;
  f.sail = "Gen-A";
  f.awa_min_deg = 90;
  f.awa_max_deg = 95;
  const Table t = findScans(db, f);
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(std::get<std::string>(t.rows[1][column(t, "controls")]), "sheet=0.2;traveller=-0.2");
  EXPECT_EQ(std::get<std::string>(t.rows[0][column(t, "boat")]), "Alpha");
  EXPECT_EQ(std::get<int64_t>(t.rows[0][column(t, "step")]), 1);

  const Table evolution = parameterEvolution(db, "t1", "camber_pct", 0.5);
  ASSERT_EQ(evolution.rows.size(), 4u);
  for (int step = 0; step < 4; ++step)
    EXPECT_DOUBLE_EQ(std::get<double>(evolution.rows[step][column(evolution, "value")]), 9.0 + step);

  const Table drive = bestTrimSteps(db, 80, 100, TrimCriterion::Drive);
  ASSERT_EQ(drive.rows.size(), 1u);
  EXPECT_DOUBLE_EQ(std::get<double>(drive.rows[0][column(drive, "drive_n")]), 150.0);
  const Table ratio = bestTrimSteps(db, 80, 100, TrimCriterion::DriveOverSide);
  EXPECT_EQ(std::get<std::string>(ratio.rows[0][column(ratio, "sail")]), "Gen-B");
  EXPECT_DOUBLE_EQ(std::get<double>(ratio.rows[0][column(ratio, "drive_side")]), 140.0 / 30.0);

  const Table both = compareSails(db, "Gen-A", "Gen-B", 94, 5);
  ASSERT_EQ(both.rows.size(), 3u);
  EXPECT_DOUBLE_EQ(std::get<double>(both.rows[0][column(both, "Gen-A.awa_deg")]), 95.0);
  EXPECT_DOUBLE_EQ(std::get<double>(both.rows[0][column(both, "Gen-B.camber_pct")]), 20.0);
  EXPECT_THROW(parameterEvolution(db, "t1", "camber", 0.5), InvalidInput);
}

TEST_P(Store, CopiesIntoAnEmptyStoreOfEitherBackendAndBack) {
  Database source = openSailDatabase(location_);
  fill(source);
  const std::string expected = allAnswers(source);
  // Into the other backend, then back into this one.
  test::TempDir other_dir;
  const std::string other = GetParam() == Backend::SQLite ? test::PgCluster::shared().createDatabase()
                                                          : other_dir.file("copy.db");
  Database there = openSailDatabase(other);
  const CopyResult r = copyStore(source, there);
  // 2 campaigns, 1 boat, 3 sails, 1 scanner unit, 2 sessions, 6 trim steps, 8
  // control settings, 4 pressures, 6 scans, 6 analyses, 18 sections.
  EXPECT_EQ(r.total_rows, 2u + 1 + 3 + 1 + 2 + 6 + 8 + 4 + 6 + 6 + 18);
  EXPECT_EQ(allAnswers(there), expected);
  EXPECT_TRUE(there.integrityCheck().empty());
  // The compressed cloud arrives byte for byte, so a re-analysis from either store is the same.
  auto cloudBlob = [](Database& db) {
    Statement s = db.prepare("SELECT cloud FROM scans WHERE cloud IS NOT NULL");
    EXPECT_TRUE(s.step());
    return s.columnBlob(0);
  };
  const std::vector<uint8_t> blob = cloudBlob(source);
  EXPECT_GT(blob.size(), 1000u);
  EXPECT_EQ(cloudBlob(there), blob);
  Database back = openSailDatabase(newLocation());
  copyStore(there, back);
  EXPECT_EQ(allAnswers(back), expected);
  EXPECT_EQ(cloudBlob(back), blob);
  EXPECT_EQ(loadScanRecord(back, 6).cloud->size(), 2000u);
  expectSameMesh(analysisSurface(back, scalar(back, "SELECT max(id) FROM analyses")), testSurface());
  // New rows after a copy take ids after the copied ones.
  ImportMetadata m;
  m.sail = "Gen-A";
  const nlohmann::json doc = analysisDoc(5.0);
  EXPECT_EQ(importScan(back, m, &doc).scan_id, 7);

  // A store that holds rows is refused, unchanged ...
  EXPECT_THROW(copyStore(source, back), InvalidInput);
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM scans"), 7);
  // ... unless appended to: campaigns, sails and trim steps merge by name (the
  // default campaign came with the import above), scans add.
  CopyOptions append;
  append.append = true;
  copyStore(source, back, append);
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM scans"), 13);
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM campaigns"), 3);
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM sails"), 3);
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM trim_steps"), 7);  // the six copied, and the one imported since
  EXPECT_EQ(scalar(back, "SELECT count(*) FROM sections"), 39);
  EXPECT_TRUE(back.integrityCheck().empty());
}

INSTANTIATE_TEST_SUITE_P(Backends, Store, ::testing::Values(Backend::SQLite, Backend::PostgreSQL), test::backendName);

// The same imports answer every query identically, byte for byte, on both.
TEST(BothBackends, AnswerEveryQueryAlike) {
  test::TempDir dir;
  std::string url;
  try {
    url = test::PgCluster::shared().createDatabase();
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
  Database lite = openSailDatabase(dir.file("a.db"));
  Database pg = openSailDatabase(url);
  fill(lite);
  fill(pg);
  const std::string answers = allAnswers(lite);
  EXPECT_GT(answers.size(), 3000u);
  EXPECT_EQ(allAnswers(pg), answers);
}

}  // namespace
}  // namespace sailshape
