// The database's read functions the reports use: a trim step's context and
// conditions, a test's steps, a scan's summary and cloud, an analysis' outline
// and sections, each read back against what an import stored.
#include <gtest/gtest.h>

#include <cmath>

#include "database/import.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "database/trim_step.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::TempDir;

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

TEST(TrimStep, ContextAndConditionsComeBackAsImported) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  const auto doc = analysisDoc(9.0);
  const ImportResult r = importScan(db, stepMeta("A2", 2), &doc);

  const std::optional<TrimStepContext> c = trimStepContext(db, r.trim_step_id);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->campaign, "Lorient");
  EXPECT_EQ(c->campaign_kind, "wind_tunnel");
  EXPECT_EQ(c->session, "morning");
  EXPECT_EQ(c->boat, "Mini 650");
  EXPECT_EQ(c->sail, "A2");
  EXPECT_EQ(c->sail_type, "gennaker");
  EXPECT_EQ(c->test, "sheet sweep");
  EXPECT_FALSE(c->design_mesh.has_value()) << "no design was stored for the sail";

  const std::optional<TrimStepConditions> k = trimStepConditions(db, r.trim_step_id);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->step_order, 2);
  ASSERT_TRUE(k->awa_deg && k->aws_m_s && k->drive_n);
  EXPECT_DOUBLE_EQ(*k->awa_deg, 112.0);
  EXPECT_DOUBLE_EQ(*k->aws_m_s, 6.5);
  EXPECT_DOUBLE_EQ(*k->drive_n, 240.0);
  EXPECT_FALSE(k->side_n.has_value()) << "a value never given stays absent";
  ASSERT_EQ(k->controls.size(), 2u);
  EXPECT_DOUBLE_EQ(k->controls.at("sheet_m"), 0.2);
  EXPECT_DOUBLE_EQ(k->controls.at("tack_height_m"), 0.3);

  EXPECT_FALSE(trimStepContext(db, r.trim_step_id + 100).has_value());
  EXPECT_FALSE(trimStepConditions(db, r.trim_step_id + 100).has_value());
}

TEST(TrimStep, ATestsStepsComeInStepOrderWithTheirNewestAnalysedScan) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  const auto doc = analysisDoc(9.0);
  // Imported out of order, and step 1 scanned twice: the second scan is its newest.
  const ImportResult s3 = importScan(db, stepMeta("A2", 3), &doc);
  const ImportResult s1 = importScan(db, stepMeta("A2", 1), &doc);
  const ImportResult s1b = importScan(db, stepMeta("A2", 1), &doc);
  const ImportResult other = importScan(db, stepMeta("A3", 1), &doc);
  ASSERT_EQ(s1.trim_step_id, s1b.trim_step_id) << "one trim step, two scans";

  const std::vector<TestStep> a2 = testSteps(db, "sheet sweep", "A2");
  ASSERT_EQ(a2.size(), 2u);
  EXPECT_EQ(a2[0].trim_step_id, s1.trim_step_id);
  EXPECT_EQ(a2[0].analysed_scan_id, s1b.scan_id);
  EXPECT_EQ(a2[1].trim_step_id, s3.trim_step_id);
  EXPECT_EQ(a2[1].analysed_scan_id, s3.scan_id);
  EXPECT_EQ(a2[0].sail, "A2");

  const std::vector<TestStep> every = testSteps(db, "sheet sweep");
  ASSERT_EQ(every.size(), 3u);
  size_t of_a3 = 0;
  for (const TestStep& s : every) of_a3 += s.trim_step_id == other.trim_step_id;
  EXPECT_EQ(of_a3, 1u);
  EXPECT_TRUE(testSteps(db, "no such test").empty());
}

TEST(TrimStep, AScansSummaryCloudOutlineAndSectionsComeBackAsImported) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  Cloud cloud;
  for (int i = 0; i < 200; ++i) cloud.points.emplace_back(0.02 * i, 0.5, 1.0);
  const auto doc = analysisDoc(11.0);
  const ImportResult r = importScan(db, stepMeta("A2", 4), &doc, &cloud);

  const std::optional<ScanSummary> s = scanSummary(db, r.scan_id);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->scanned_at, "2026-06-14T10:30:00Z");
  EXPECT_EQ(s->trim_step_id, r.trim_step_id);
  EXPECT_EQ(s->analysis_id, r.analysis_id);
  EXPECT_FALSE(scanSummary(db, r.scan_id + 100).has_value());

  const std::optional<Cloud> back = scanCloud(db, r.scan_id);
  ASSERT_TRUE(back.has_value());
  ASSERT_EQ(back->size(), 200u);
  // The blob keeps float32: 10 µm at these distances (cloud_blob.hpp).
  EXPECT_NEAR(back->points[199].x(), 3.98, 1e-5);

  const nlohmann::json outline = nlohmann::json::parse(analysisOutlineJson(db, r.analysis_id));
  EXPECT_DOUBLE_EQ(outline.at("area_m2").get<double>(), 20.0);

  const std::vector<Section> sections = analysisSections(db, r.analysis_id);
  ASSERT_EQ(sections.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sections[k].fraction, (k + 1) / 4.0, 1e-12);
    EXPECT_DOUBLE_EQ(sections[k].value.camber_pct, 11.0 + k);
    EXPECT_TRUE(std::isnan(sections[k].value.exit_deg)) << "stored as NULL: not measured";
  }
  EXPECT_TRUE(analysisSections(db, r.analysis_id + 100).empty());
}

}  // namespace
}  // namespace sailshape
