// The catalogue and the read functions the reports and the viewer use, on both
// backends: sails with their design, calibrations, registrations, design
// comparisons, trim steps, a test's steps and a scan's later analyses.
#include <gtest/gtest.h>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "database/trim_step.hpp"
#include "store_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;

class StoreCatalog : public test::StoreTest {};

Mesh square() {
  Mesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0.1, 1)};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

ImportMetadata stepMeta(const std::string& sail, int step) {
  ImportMetadata meta;
  meta.campaign = "Lorient";
  meta.campaign_kind = "wind_tunnel";
  meta.session = "morning";
  meta.boat = "Mini 650";
  meta.sail = sail;
  meta.sail_type = "gennaker";
  meta.test = "sheet sweep";
  meta.trim_step = step;
  meta.awa_deg = 110.0 + step;
  meta.aws_m_s = 6.5;
  meta.drive_n = 120.0 * step;
  meta.controls = {{"sheet_m", 0.1 * step}, {"tack_height_m", 0.3}};
  meta.scanned_at = "2026-06-1" + std::to_string(step) + "T10:30:00Z";
  return meta;
}

TEST_P(StoreCatalog, SailsCalibrationsRegistrationsAndComparisons) {
  Database db = openSailDatabase(location_);
  const Mesh mesh = square();
  const nlohmann::json params = {{"luff_m", 10.5}};
  const int64_t id = upsertSail(db, {"Main-1", "mainsail", "M", "Loft A", "v2", "Alpha"}, &mesh, &params);
  EXPECT_EQ(upsertSail(db, {"Main-1", "", "", "", "v3", ""}), id);  // updates, keeps the rest
  const Mesh back = sailDesignMesh(db, "Main-1");
  ASSERT_EQ(back.vertices.size(), 4u);
  EXPECT_EQ(back.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_DOUBLE_EQ(back.vertices[3].y(), 0.1);
  EXPECT_THROW(sailDesignMesh(db, "nope"), InvalidInput);

  addCalibration(db, "LMS511-7", {"2025-03-01", 0.061, 0.8});
  addCalibration(db, "LMS511-7", {"2025-06-01", 0.062, 0.5});
  EXPECT_FALSE(calibrationAt(db, "LMS511-7", "2025-01-01"));
  EXPECT_DOUBLE_EQ(calibrationAt(db, "LMS511-7", "2025-05-20T10:00:00Z")->p_m, 0.061);
  EXPECT_DOUBLE_EQ(calibrationAt(db, "LMS511-7", "2025-07-01")->theta_deg, 0.5);

  const nlohmann::json doc = analysisDoc(9.0);
  ImportMetadata m;
  m.sail = "Main-1";
  const ImportResult r = importScan(db, m, &doc);
  Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
  t(0, 3) = 1.5;
  t(1, 0) = 0.25;
  addRegistration(db, r.scan_id, t, 0.98, 0.003);
  EXPECT_TRUE(scanTransform(db, r.scan_id).isApprox(t, 1e-15));
  EXPECT_THROW(addRegistration(db, 9999, t, 1, 0), DatabaseError);  // foreign key
  DistanceStats stats;
  stats.count = 1000;
  stats.rms_m = 0.02;
  stats.p95_m = 0.05;
  addDesignComparison(db, r.analysis_id, "Main-1", stats);
  Statement s = db.prepare("SELECT rms_m, stats FROM design_comparisons");
  ASSERT_TRUE(s.step());
  EXPECT_DOUBLE_EQ(s.columnDouble(0), 0.02);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(s.columnText(1))["p95_m"].get<double>(), 0.05);

  const ScanRecord record = loadScanRecord(db, r.scan_id);
  EXPECT_TRUE(record.has_design);
  ASSERT_TRUE(record.registration.has_value());
  EXPECT_DOUBLE_EQ((*record.registration)(1, 0), 0.25);
  EXPECT_TRUE(db.integrityCheck().empty());
}

TEST_P(StoreCatalog, TrimStepsTestsAndLaterAnalysesComeBackAsImported) {
  Database db = openSailDatabase(location_);
  const auto doc = analysisDoc(9.0);
  const ImportResult s3 = importScan(db, stepMeta("A2", 3), &doc);
  const ImportResult s1 = importScan(db, stepMeta("A2", 1), &doc);
  const ImportResult s1b = importScan(db, stepMeta("A2", 1), &doc);
  importScan(db, stepMeta("A3", 1), &doc);
  ASSERT_EQ(s1.trim_step_id, s1b.trim_step_id) << "one trim step, two scans";

  const std::optional<TrimStepContext> c = trimStepContext(db, s3.trim_step_id);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->campaign_kind, "wind_tunnel");
  EXPECT_EQ(c->boat, "Mini 650");
  EXPECT_FALSE(c->design_mesh.has_value());
  const std::optional<TrimStepConditions> k = trimStepConditions(db, s3.trim_step_id);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->step_order, 3);
  EXPECT_DOUBLE_EQ(*k->drive_n, 360.0);
  EXPECT_FALSE(k->side_n.has_value());
  EXPECT_DOUBLE_EQ(k->controls.at("sheet_m"), 0.30000000000000004);  // 0.1 * 3, kept to the last bit

  const std::vector<TestStep> a2 = testSteps(db, "sheet sweep", "A2");
  ASSERT_EQ(a2.size(), 2u);
  EXPECT_EQ(a2[0].analysed_scan_id, s1b.scan_id);
  EXPECT_EQ(a2[1].analysed_scan_id, s3.scan_id);
  EXPECT_EQ(testSteps(db, "sheet sweep").size(), 3u);

  const int64_t later = addAnalysis(db, s1.scan_id, analysisDoc(11.0, 2));
  EXPECT_EQ(latestAnalysisId(db, s1.scan_id), later);
  ASSERT_EQ(analysisSections(db, later).size(), 2u);
  EXPECT_DOUBLE_EQ(analysisSections(db, later)[1].value.camber_pct, 12.0);
  EXPECT_EQ(scanSummary(db, s1.scan_id)->scanned_at, "2026-06-11T10:30:00Z");
  EXPECT_FALSE(scanSummary(db, 9999).has_value());
  EXPECT_THROW(addAnalysis(db, 9999, doc), InvalidInput);
}

INSTANTIATE_TEST_SUITE_P(Backends, StoreCatalog, ::testing::Values(Backend::SQLite, Backend::PostgreSQL),
                         test::backendName);

}  // namespace
}  // namespace sailshape
