#include <gtest/gtest.h>

#include <cmath>

#include "analysis/core/errors.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::TempDir;

Cloud lineCloud(size_t n) {
  Cloud c;
  for (size_t i = 0; i < n; ++i) c.points.emplace_back(0.01 * double(i), 0.5, 2.0);
  return c;
}

TEST(ScanRecord, ReadsBackWhatImportStored) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  ImportMetadata meta;
  meta.campaign = "Lorient";
  meta.sail = "J1";
  meta.test = "upwind";
  meta.trim_step = 4;
  meta.awa_deg = 31.5;
  meta.settings = {{"frequency_hz", 25}};
  const Cloud cloud = lineCloud(500);
  const auto doc = analysisDoc(10.0);
  const ImportResult imported = importScan(db, meta, &doc, &cloud);

  ScanRecord r = loadScanRecord(db, imported.scan_id);
  EXPECT_EQ(r.settings.value("frequency_hz", 0), 25);
  EXPECT_FALSE(r.registration.has_value());
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  transform.block<3, 1>(0, 3) = Vec3(1.5, -2.0, 0.25);
  addRegistration(db, imported.scan_id, transform, 0.004, 0.004);
  r = loadScanRecord(db, imported.scan_id);
  ASSERT_TRUE(r.registration.has_value());
  EXPECT_DOUBLE_EQ((*r.registration)(1, 3), -2.0);
  EXPECT_EQ(r.scan_id, imported.scan_id);
  EXPECT_EQ(r.analysis_id, imported.analysis_id);
  EXPECT_EQ(r.campaign, "Lorient");
  EXPECT_EQ(r.sail, "J1");
  EXPECT_EQ(r.test, "upwind");
  EXPECT_EQ(r.step, 4);
  ASSERT_TRUE(r.awa_deg.has_value());
  EXPECT_DOUBLE_EQ(*r.awa_deg, 31.5);
  EXPECT_FALSE(r.has_design);
  ASSERT_TRUE(r.cloud.has_value());
  ASSERT_EQ(r.cloud->size(), 500u);
  // The blob keeps float32: 10 µm at these distances (cloud_blob.hpp).
  EXPECT_NEAR(r.cloud->points[499].x(), 4.99, 1e-5);
  ASSERT_EQ(r.sections.sections.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const Section& s = r.sections.sections[k];
    EXPECT_NEAR(s.fraction, (k + 1) / 4.0, 1e-12);
    EXPECT_DOUBLE_EQ(s.value.camber_pct, 10.0 + k);
    EXPECT_DOUBLE_EQ(s.value.draft_pct, 40.0 + k);
    EXPECT_DOUBLE_EQ(s.uncertainty.camber_pct, 0.2);
    EXPECT_TRUE(std::isnan(s.value.exit_deg)) << "a NULL parameter must stay visible as not measured";
    ASSERT_EQ(s.curve.size(), 3u);
    EXPECT_DOUBLE_EQ(s.luff_point.z(), s.fraction);
    EXPECT_DOUBLE_EQ(s.leech_point.x(), 2.0);
  }
  EXPECT_DOUBLE_EQ(r.analysis_params["sensor_sigma_m"].get<double>(), 0.004);
}

TEST(ScanRecord, SectionsTheAnalysisCouldNotMeasureComeBackWithWhy) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  ImportMetadata meta;
  meta.campaign = "Lorient";
  meta.sail = "J1";
  auto doc = analysisDoc(10.0, 2);  // measured at 1/3 and 2/3
  const std::string why = "the section plane at fraction 0.900 leaves 14 % of the chord at the leech uncovered";
  doc["unmeasured_sections"] = {{{"fraction", 0.9}, {"reason", why}}};
  const ImportResult imported = importScan(db, meta, &doc, nullptr);
  const ScanRecord r = loadScanRecord(db, imported.scan_id);
  EXPECT_EQ(r.sections.sections.size(), 2u);
  ASSERT_EQ(r.sections.unmeasured.size(), 1u);
  EXPECT_DOUBLE_EQ(r.sections.unmeasured[0].fraction, 0.9);
  EXPECT_EQ(r.sections.unmeasured[0].reason, why);
  // The rest of the diagnostics is stored as it was.
  Statement s = db.prepare("SELECT diagnostics FROM analyses WHERE id = ?");
  s.bind(1, imported.analysis_id);
  ASSERT_TRUE(s.step());
  EXPECT_EQ(nlohmann::json::parse(s.columnText(0))["points_in"].get<int>(), 50000);

  // An analysis without any keeps an empty list.
  const auto plain = analysisDoc(10.0);
  EXPECT_TRUE(loadScanRecord(db, importScan(db, meta, &plain, nullptr).scan_id).sections.unmeasured.empty());
}

TEST(ScanRecord, ScanWithoutCloudOrAnalysis) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  ImportMetadata meta;
  const auto doc = analysisDoc(8.0);
  const ImportResult only_doc = importScan(db, meta, &doc);
  EXPECT_FALSE(loadScanRecord(db, only_doc.scan_id).cloud.has_value());
  const Cloud cloud = lineCloud(10);
  meta.trim_step = 1;
  const ImportResult only_cloud = importScan(db, meta, nullptr, &cloud);
  const ScanRecord r = loadScanRecord(db, only_cloud.scan_id);
  EXPECT_EQ(r.analysis_id, 0);
  EXPECT_TRUE(r.sections.sections.empty());
  EXPECT_TRUE(r.analysis_params.is_null());
}

TEST(ScanRecord, KnowsWhetherTheSailHasADesign) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  Mesh design;
  design.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
  design.triangles = {{0, 1, 2}};
  SailInfo info;
  info.name = "main";
  upsertSail(db, info, &design);
  ImportMetadata meta;
  meta.sail = "main";
  const auto doc = analysisDoc(8.0);
  EXPECT_TRUE(loadScanRecord(db, importScan(db, meta, &doc).scan_id).has_design);
}

TEST(ScanRecord, MissingScanThrows) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  EXPECT_THROW(loadScanRecord(db, 42), InvalidInput);
}

TEST(AddAnalysis, BecomesTheScansLatestAndKeepsTheEarlierOne) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  ImportMetadata meta;
  const auto first = analysisDoc(8.0);
  const ImportResult imported = importScan(db, meta, &first);
  const int64_t id = addAnalysis(db, imported.scan_id, analysisDoc(12.0, 5));
  EXPECT_GT(id, imported.analysis_id);
  const ScanRecord r = loadScanRecord(db, imported.scan_id);
  EXPECT_EQ(r.analysis_id, id);
  ASSERT_EQ(r.sections.sections.size(), 5u);
  EXPECT_DOUBLE_EQ(r.sections.sections[0].value.camber_pct, 12.0);
  Statement count = db.prepare("SELECT count(*) FROM analyses WHERE scan_id = ?");
  count.bind(1, imported.scan_id);
  count.step();
  EXPECT_EQ(count.columnInt(0), 2);
}

TEST(AddAnalysis, RefusesBadInputAndStoresNothing) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  ImportMetadata meta;
  const auto doc = analysisDoc(8.0);
  const ImportResult imported = importScan(db, meta, &doc);
  EXPECT_THROW(addAnalysis(db, imported.scan_id + 1, doc), InvalidInput);
  EXPECT_THROW(addAnalysis(db, imported.scan_id, nlohmann::json{{"sail", {}}}), InvalidInput);
  auto bad = analysisDoc(9.0);
  bad["sections"][2]["fraction"] = 1.5;
  EXPECT_THROW(addAnalysis(db, imported.scan_id, bad), InvalidInput);
  Statement count = db.prepare("SELECT count(*) FROM analyses");
  count.step();
  EXPECT_EQ(count.columnInt(0), 1) << "a refused analysis must leave no row behind";
  EXPECT_EQ(loadScanRecord(db, imported.scan_id).analysis_id, imported.analysis_id);
}

}  // namespace
}  // namespace sailshape
