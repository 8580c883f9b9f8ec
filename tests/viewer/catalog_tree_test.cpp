#include <gtest/gtest.h>

#include "database/import.hpp"
#include "database/schema.hpp"
#include "viewer/catalog_tree.hpp"
#include "viewer_fixture.hpp"

namespace sailshape::viewer {
namespace {

nlohmann::json oneSection() {
  return {{"sections", nlohmann::json::array({{{"fraction", 0.5}, {"camber_pct", 11.0}}})}};
}

ImportResult add(Database& db, const std::string& campaign, const std::string& test, int step, const std::string& sail,
                 std::optional<double> awa = std::nullopt) {
  ImportMetadata m;
  m.campaign = campaign;
  m.test = test;
  m.trim_step = step;
  m.sail = sail;
  m.awa_deg = awa;
  if (step == 2) m.controls = {{"sheet", 0.4}};
  const auto doc = oneSection();
  return importScan(db, m, &doc);
}

TEST(CatalogTree, GroupsCampaignTestStepScan) {
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("c.sqlite"));
  const auto a = add(db, "Lorient", "upwind", 1, "J1", 32.0);
  const auto b = add(db, "Lorient", "upwind", 1, "J1", 32.0);  // a second scan of the same trim step
  const auto c = add(db, "Lorient", "upwind", 2, "J1", 35.0);
  const auto d = add(db, "Lorient", "upwind", 2, "J2", 35.0);  // another sail at the same step order
  const auto e = add(db, "Lorient", "reaching", 1, "A2");
  const auto f = add(db, "Auckland", "", 1, "M1");

  const CatalogTree tree = loadCatalogTree(db);
  EXPECT_EQ(tree.scan_count, 6u);
  ASSERT_EQ(tree.campaigns.size(), 2u);
  EXPECT_EQ(tree.campaigns[0].name, "Auckland");  // ordered by name
  ASSERT_EQ(tree.campaigns[0].tests.size(), 1u);
  EXPECT_EQ(tree.campaigns[0].tests[0].label(), "(no test name)");

  const CampaignEntry& lorient = tree.campaigns[1];
  ASSERT_EQ(lorient.tests.size(), 2u);
  EXPECT_EQ(lorient.tests[0].name, "reaching");
  const TestEntry& upwind = lorient.tests[1];
  ASSERT_EQ(upwind.steps.size(), 3u);
  EXPECT_EQ(upwind.steps[0].step, 1);
  ASSERT_EQ(upwind.steps[0].scans.size(), 2u);
  EXPECT_EQ(upwind.steps[0].scans[0].scan_id, a.scan_id);
  EXPECT_EQ(upwind.steps[0].scans[1].scan_id, b.scan_id);
  EXPECT_EQ(upwind.steps[1].sail, "J1");
  EXPECT_EQ(upwind.steps[2].sail, "J2");
  EXPECT_EQ(upwind.steps[1].controls, "sheet=0.4");
  EXPECT_EQ(upwind.steps[1].label(), "step 2 · J1 · AWA 35°");
  EXPECT_EQ(lorient.tests[0].steps[0].label(), "step 1 · A2");

  EXPECT_EQ(tree.scanIds(), (std::vector<int64_t>{f.scan_id, e.scan_id, a.scan_id, b.scan_id, c.scan_id, d.scan_id}));
  ASSERT_NE(tree.stepOf(d.scan_id), nullptr);
  EXPECT_EQ(tree.stepOf(d.scan_id)->sail, "J2");
  EXPECT_EQ(tree.stepOf(999), nullptr);
}

TEST(CatalogTree, EmptyDatabaseGivesAnEmptyTree) {
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("empty.sqlite"));
  const CatalogTree tree = loadCatalogTree(db);
  EXPECT_TRUE(tree.campaigns.empty());
  EXPECT_EQ(tree.scan_count, 0u);
  EXPECT_TRUE(tree.scanIds().empty());
}

}  // namespace
}  // namespace sailshape::viewer
