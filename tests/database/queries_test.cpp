#include <gtest/gtest.h>

#include "analysis/core/errors.hpp"
#include "database/import.hpp"
#include "database/queries.hpp"
#include "database/schema.hpp"
#include "database/table_export.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::TempDir;

double num(const Value& v) {
  if (std::holds_alternative<double>(v)) return std::get<double>(v);
  if (std::holds_alternative<int64_t>(v)) return double(std::get<int64_t>(v));
  ADD_FAILURE() << "not a number";
  return 0;
}
std::string str(const Value& v) { return std::holds_alternative<std::string>(v) ? std::get<std::string>(v) : "<not text>"; }
size_t col(const Table& t, const std::string& name) {
  for (size_t i = 0; i < t.columns.size(); ++i)
    if (t.columns[i] == name) return i;
  ADD_FAILURE() << "no column " << name;
  return 0;
}

// Gen-A (genoa, boat Alpha, campaign Lorient): test "t1", steps 0..3 at AWA 80,
// 90, 95, 100, drive 100/150/130/120 N, side 50/60/40/80 N, sheet 0.1·step,
// camber at section k = 8 + step + k. Gen-B (genoa, no boat): step 0 at AWA 94,
// drive 140, side 30, camber 20 + k. Main (mainsail, wind tunnel): AWA 30.
class Queries : public ::testing::Test {
 protected:
  void SetUp() override {
    db_ = std::make_unique<Database>(openSailDatabase(dir_.file("q.db")));
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
      const nlohmann::json doc = analysisDoc(8.0 + step);
      importScan(*db_, m, &doc);
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
    importScan(*db_, b, &doc_b);
    ImportMetadata m;
    m.campaign = "Tunnel";
    m.campaign_kind = "wind_tunnel";
    m.sail = "Main";
    m.sail_type = "mainsail";
    m.awa_deg = 30;
    const nlohmann::json doc_m = analysisDoc(12.0);
    importScan(*db_, m, &doc_m);
  }
  TempDir dir_;
  std::unique_ptr<Database> db_;
};

TEST_F(Queries, FindScansByEveryFilter) {
  EXPECT_EQ(findScans(*db_).rows.size(), 6u);
  ScanFilter f;
  f.sail = "Gen-A";
  EXPECT_EQ(findScans(*db_, f).rows.size(), 4u);
  f = {};
  f.sail_type = "genoa";
  EXPECT_EQ(findScans(*db_, f).rows.size(), 5u);
  f = {};
  f.boat = "Alpha";
  EXPECT_EQ(findScans(*db_, f).rows.size(), 4u);
  f = {};
  f.campaign = "Tunnel";
  const Table tunnel = findScans(*db_, f);
  ASSERT_EQ(tunnel.rows.size(), 1u);
  EXPECT_EQ(str(tunnel.rows[0][col(tunnel, "sail")]), "Main");
  f = {};
  f.awa_min_deg = 90;
  f.awa_max_deg = 100;
  EXPECT_EQ(findScans(*db_, f).rows.size(), 4u);
  f = {};
  f.control = "sheet";
  f.control_min = 0.15;
  f.control_max = 0.35;
  const Table sheet = findScans(*db_, f);
  ASSERT_EQ(sheet.rows.size(), 2u);
  EXPECT_EQ(num(sheet.rows[0][col(sheet, "step")]), 2);
  EXPECT_EQ(str(sheet.rows[0][col(sheet, "controls")]), "sheet=0.2;traveller=-0.2");
  f = {};
  f.test = "t1";
  f.sail_type = "mainsail";
  EXPECT_TRUE(findScans(*db_, f).rows.empty());

  f = {};
  f.awa_min_deg = 100;
  f.awa_max_deg = 90;
  EXPECT_THROW(findScans(*db_, f), InvalidInput);
  f = {};
  f.control_min = 1;
  EXPECT_THROW(findScans(*db_, f), InvalidInput);
}

TEST_F(Queries, FindSectionsReturnsStoredValues) {
  ScanFilter f;
  f.sail = "Gen-A";
  f.test = "t1";
  const Table t = findSections(*db_, f);
  ASSERT_EQ(t.rows.size(), 12u);
  // step 2, middle section
  const auto& row = t.rows[7];
  EXPECT_EQ(num(row[col(t, "step")]), 2);
  EXPECT_DOUBLE_EQ(num(row[col(t, "fraction")]), 0.5);
  EXPECT_DOUBLE_EQ(num(row[col(t, "camber_pct")]), 11.0);
  EXPECT_DOUBLE_EQ(num(row[col(t, "u_draft_pct")]), 1.0);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(row[col(t, "exit_deg")]));
}

TEST_F(Queries, ParameterEvolutionOverTheTrimSteps) {
  const Table t = parameterEvolution(*db_, "t1", "camber_pct", 0.45);
  ASSERT_EQ(t.rows.size(), 4u);
  for (int step = 0; step < 4; ++step) {
    EXPECT_EQ(num(t.rows[step][col(t, "step")]), step);
    EXPECT_DOUBLE_EQ(num(t.rows[step][col(t, "fraction")]), 0.5);
    EXPECT_DOUBLE_EQ(num(t.rows[step][col(t, "value")]), 9.0 + step);
    EXPECT_DOUBLE_EQ(num(t.rows[step][col(t, "uncertainty")]), 0.2);
  }
  EXPECT_THROW(parameterEvolution(*db_, "t1", "camber; DROP TABLE scans", 0.5), InvalidInput);

  // A step that could not measure its 0.5 section has no value there, not its 0.25 or 0.75 one.
  ImportMetadata m;
  m.campaign = "Lorient";
  m.sail = "Gen-A";
  m.test = "t1";
  m.trim_step = 4;
  nlohmann::json doc = analysisDoc(12.0);
  doc["sections"].erase(1);
  doc["unmeasured_sections"] = {{{"fraction", 0.5}, {"reason", "crosses a hole"}}};
  importScan(*db_, m, &doc);
  const Table u = parameterEvolution(*db_, "t1", "camber_pct", 0.5);
  ASSERT_EQ(u.rows.size(), 5u);
  EXPECT_DOUBLE_EQ(num(u.rows[3][col(u, "value")]), 12.0);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(u.rows[4][col(u, "value")]));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(u.rows[4][col(u, "fraction")]));
  // Nearer its measured 0.75 than the unmeasured 0.5: that section's value stands.
  EXPECT_DOUBLE_EQ(num(parameterEvolution(*db_, "t1", "camber_pct", 0.7).rows[4][col(u, "value")]), 14.0);
  EXPECT_THROW(parameterEvolution(*db_, "t1", "camber_pct", 1.0), InvalidInput);
}

TEST_F(Queries, TwoSailsSideBySideAtTheSameAwa) {
  const Table t = compareSails(*db_, "Gen-A", "Gen-B", 95.0, 5.0);
  ASSERT_EQ(t.rows.size(), 3u);
  EXPECT_DOUBLE_EQ(num(t.rows[1][col(t, "fraction")]), 0.5);
  EXPECT_DOUBLE_EQ(num(t.rows[1][col(t, "Gen-A.awa_deg")]), 95.0);
  EXPECT_DOUBLE_EQ(num(t.rows[1][col(t, "Gen-A.camber_pct")]), 11.0);
  EXPECT_DOUBLE_EQ(num(t.rows[1][col(t, "Gen-B.awa_deg")]), 94.0);
  EXPECT_DOUBLE_EQ(num(t.rows[1][col(t, "Gen-B.camber_pct")]), 21.0);
  // No Gen-B near 60°: its columns stay empty.
  const Table none = compareSails(*db_, "Gen-A", "Gen-B", 80.0, 2.0);
  ASSERT_EQ(none.rows.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(none.rows[0][col(none, "Gen-B.scan_id")]));
  EXPECT_THROW(compareSails(*db_, "Gen-A", "Gen-A", 95.0), InvalidInput);
  EXPECT_THROW(compareSails(*db_, "Gen-A", "Gen-B", 95.0, -1.0), InvalidInput);
}

TEST_F(Queries, BestTrimStepByDriveAndByDriveOverSide) {
  const Table drive = bestTrimSteps(*db_, 85, 100, TrimCriterion::Drive);
  ASSERT_EQ(drive.rows.size(), 1u);
  EXPECT_EQ(str(drive.rows[0][col(drive, "sail")]), "Gen-A");
  EXPECT_EQ(num(drive.rows[0][col(drive, "step")]), 1);
  EXPECT_DOUBLE_EQ(num(drive.rows[0][col(drive, "drive_n")]), 150);

  const Table ratio = bestTrimSteps(*db_, 85, 100, TrimCriterion::DriveOverSide, 2);
  ASSERT_EQ(ratio.rows.size(), 2u);
  EXPECT_EQ(str(ratio.rows[0][col(ratio, "sail")]), "Gen-B");
  EXPECT_NEAR(num(ratio.rows[0][col(ratio, "drive_side")]), 140.0 / 30.0, 1e-12);
  EXPECT_EQ(num(ratio.rows[1][col(ratio, "step")]), 2);

  ScanFilter only_a;
  only_a.sail = "Gen-A";
  const Table a = bestTrimSteps(*db_, 85, 100, TrimCriterion::DriveOverSide, 1, only_a);
  EXPECT_EQ(num(a.rows[0][col(a, "step")]), 2);
  EXPECT_THROW(bestTrimSteps(*db_, 100, 85, TrimCriterion::Drive), InvalidInput);
  EXPECT_THROW(bestTrimSteps(*db_, 85, 100, TrimCriterion::Drive, 0), InvalidInput);
}

TEST_F(Queries, BackupHoldsTheSameQueryResults) {
  db_->backupTo(dir_.file("copy.db"));
  Database copy = openSailDatabase(dir_.file("copy.db"));
  EXPECT_EQ(tableToCsv(findSections(copy)), tableToCsv(findSections(*db_)));
  EXPECT_EQ(tableToCsv(findScans(copy)), tableToCsv(findScans(*db_)));
}

TEST(TableExport, CsvQuotesAndNulls) {
  Table t;
  t.columns = {"id", "name", "value"};
  t.rows.push_back({int64_t{1}, std::string("plain"), 0.25});
  t.rows.push_back({int64_t{2}, std::string("a,\"b\""), Value{}});
  EXPECT_EQ(tableToCsv(t), "id,name,value\n1,plain,0.25\n2,\"a,\"\"b\"\"\",\n");
  const nlohmann::ordered_json j = tableToJson(t);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["id"], 1);
  EXPECT_EQ(j[0]["name"], "plain");
  EXPECT_DOUBLE_EQ(j[0]["value"].get<double>(), 0.25);
  EXPECT_TRUE(j[1]["value"].is_null());
  EXPECT_EQ(j[1]["name"], "a,\"b\"");
}

TEST_F(Queries, ExportWritesFiles) {
  ScanFilter f;
  f.campaign = "Tunnel";
  const Table t = findScans(*db_, f);
  writeTable(dir_.file("out.csv"), t, "csv");
  writeTable(dir_.file("out.json"), t, "json");
  const std::string csv = test::readBytes(dir_.file("out.csv"));
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "scan_id,campaign,boat,sail,sail_type,test,step,awa_deg,aws_m_s,drive_n,side_n,heel_moment_nm,point_count,"
            "scanned_at,controls");
  EXPECT_NE(csv.find(",Tunnel,,Main,mainsail,,0,30,"), std::string::npos) << csv;
  const nlohmann::json j = nlohmann::json::parse(test::readBytes(dir_.file("out.json")));
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["sail"], "Main");
  EXPECT_DOUBLE_EQ(j[0]["awa_deg"].get<double>(), 30.0);
  EXPECT_TRUE(j[0]["boat"].is_null());
  EXPECT_THROW(writeTable(dir_.file("out.xml"), t, "xml"), InvalidInput);
  EXPECT_THROW(writeTable(dir_.file("no/dir/out.csv"), t, "csv"), FileError);
}

}  // namespace
}  // namespace sailshape
