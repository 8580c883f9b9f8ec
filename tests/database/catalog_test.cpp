#include <gtest/gtest.h>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/schema.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::TempDir;

int64_t scalar(Database& db, const std::string& sql) {
  Statement s = db.prepare(sql);
  s.step();
  return s.columnInt(0);
}

Mesh square() {
  Mesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0.1, 1)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// `db design add` on a sail: each call a new version, the sail created when new;
// a design without triangles or with a NaN vertex stores nothing at all.
TEST(Catalog, DesignVersionsCountUpAndBadDesignsStoreNothing) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("v.db"));
  EXPECT_THROW(designVersions(db, "Main"), InvalidInput);
  EXPECT_THROW(designVersionMesh(db, "Main"), InvalidInput);
  EXPECT_EQ(currentDesignVersion(db, "Main"), 0);
  Mesh empty;
  EXPECT_THROW(addDesignVersion(db, "Main", empty, {}), InvalidInput);
  Mesh nan = square();
  nan.vertices[1].x() = std::nan("");
  EXPECT_THROW(addDesignVersion(db, "Main", nan, {}), InvalidInput);
  EXPECT_THROW(addDesignVersion(db, "", square(), {}), InvalidInput);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM sails"), 0) << "a refused design created its sail";
  EXPECT_EQ(addDesignVersion(db, "Main", square(), {"a.obj", "obj", "m", "boat"}), 1);
  EXPECT_EQ(addDesignVersion(db, "Main", square(), {"b.dxf", "dxf", "mm", "sailcut"}), 2);
  EXPECT_THROW(addDesignVersion(db, "Main", nan, {}), InvalidInput);
  EXPECT_EQ(currentDesignVersion(db, "Main"), 2);
  EXPECT_THROW(designVersionMesh(db, "Main", 3), InvalidInput);
  const std::vector<DesignVersion> v = designVersions(db, "Main");
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[1].source.format, "dxf");
  EXPECT_EQ(v[1].source.unit, "mm");
  EXPECT_EQ(v[1].triangles, 2u);
  // The demo stores its designs at every run: the same mesh again is no new version.
  const Mesh same = square();
  upsertSail(db, {"Main", "", "", "", "", ""}, &same);
  EXPECT_EQ(currentDesignVersion(db, "Main"), 2);
}

TEST(Catalog, SailWithDesignMeshAndParameters) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("c.db"));
  const Mesh mesh = square();
  const nlohmann::json params = {{"luff_m", 10.5}};
  const int64_t id = upsertSail(db, {"Main-1", "mainsail", "M", "Loft A", "v2", "Alpha"}, &mesh, &params);
  EXPECT_EQ(upsertSail(db, {"Main-1", "", "", "", "v3", ""}), id);  // updates, keeps the rest
  const Mesh back = sailDesignMesh(db, "Main-1");
  ASSERT_EQ(back.vertices.size(), 4u);
  EXPECT_EQ(back.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_DOUBLE_EQ(back.vertices[3].y(), 0.1);
  Statement s = db.prepare("SELECT type, version, design_params, (SELECT name FROM boats WHERE id = boat_id) FROM sails");
  ASSERT_TRUE(s.step());
  EXPECT_EQ(s.columnText(0), "mainsail");
  EXPECT_EQ(s.columnText(1), "v3");
  EXPECT_EQ(nlohmann::json::parse(s.columnText(2))["luff_m"], 10.5);
  EXPECT_EQ(s.columnText(3), "Alpha");

  EXPECT_THROW(upsertSail(db, {}), InvalidInput);
  EXPECT_THROW(sailDesignMesh(db, "nope"), InvalidInput);
  SailInfo jib;
  jib.name = "Jib";
  upsertSail(db, jib);
  EXPECT_THROW(sailDesignMesh(db, "Jib"), InvalidInput);
  EXPECT_THROW(unpackMesh({1, 2, 3}), DatabaseError);
  std::vector<uint8_t> bad = packMesh(mesh);
  bad.back() = 0xff;  // an index beyond the vertices
  EXPECT_THROW(unpackMesh(bad), DatabaseError);
}

TEST(Catalog, CalibrationHistoryAnswersTheOneInForce) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("c.db"));
  addCalibration(db, "LMS511-7", {"2025-03-01", 0.061, 0.8});
  addCalibration(db, "LMS511-7", {"2025-06-01", 0.062, 0.5});
  EXPECT_FALSE(calibrationAt(db, "LMS511-7", "2025-01-01"));
  const auto c = calibrationAt(db, "LMS511-7", "2025-05-20T10:00:00Z");
  ASSERT_TRUE(c);
  EXPECT_DOUBLE_EQ(c->p_m, 0.061);
  EXPECT_DOUBLE_EQ(calibrationAt(db, "LMS511-7", "2025-07-01")->theta_deg, 0.5);
  EXPECT_THROW(addCalibration(db, "", {"2025-03-01", 0.06, 0.8}), InvalidInput);
  EXPECT_THROW(addCalibration(db, "X", {"", 0.06, 0.8}), InvalidInput);
}

TEST(Catalog, RegistrationAndDesignComparisonOfAScan) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("c.db"));
  ImportMetadata m;
  m.sail = "Main-1";
  const nlohmann::json doc = test::analysisDoc(9.0);
  const ImportResult r = importScan(db, m, &doc);
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t(0, 3) = 1.5;
  t(1, 0) = 0.25;
  addRegistration(db, r.scan_id, t, 0.98, 0.003);
  EXPECT_TRUE(scanTransform(db, r.scan_id).isApprox(t));
  EXPECT_THROW(addRegistration(db, 9999, t, 1, 0), DatabaseError);  // foreign key
  t(2, 2) = NAN;
  EXPECT_THROW(addRegistration(db, r.scan_id, t, 1, 0), InvalidInput);
  EXPECT_THROW(scanTransform(db, 9999), InvalidInput);

  DistanceStats stats;
  stats.count = 1000;
  stats.mean_m = 0.01;
  stats.rms_m = 0.02;
  stats.max_abs_m = 0.08;
  stats.p95_m = 0.05;
  addDesignComparison(db, r.analysis_id, "Main-1", stats);
  Statement s = db.prepare("SELECT rms_m, stats FROM design_comparisons");
  ASSERT_TRUE(s.step());
  EXPECT_DOUBLE_EQ(s.columnDouble(0), 0.02);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(s.columnText(1))["p95_m"].get<double>(), 0.05);
  EXPECT_THROW(addDesignComparison(db, r.analysis_id, "nope", stats), InvalidInput);
  EXPECT_TRUE(db.integrityCheck().empty());
}

}  // namespace
}  // namespace sailshape
