// `sailshape db` on a PostgreSQL store and `db copy` between stores, run as a
// user would: the same answers, byte for byte, from a server and from its copies.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/cli/run_sailshape.hpp"
#include "tests/database/pg_cluster.hpp"

namespace {

namespace fs = std::filesystem;

using sailshape::testing::Outcome;

class DbCopyCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sailshape-dbcopy-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    try {
      pg_ = sailshape::test::PgCluster::shared().createDatabase();
    } catch (const std::exception& e) {
      FAIL() << e.what();
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  Outcome run(const std::string& args) { return sailshape::testing::runSailshape(dir_, args); }

  // An analysis document like `sailshape analyze --json`'s: sections at 0.25,
  // 0.5 and 0.75 with camber base + k % and draft 40 + k %.
  std::string analysisJson(double camber, const std::string& name) {
    nlohmann::json doc;
    doc["sail"] = {{"area_m2", 20.0}};
    doc["diagnostics"] = {{"points_in", 50000}};
    doc["sections"] = nlohmann::json::array();
    for (int k = 0; k < 3; ++k) {
      const double f = (k + 1) / 4.0;
      doc["sections"].push_back({{"fraction", f}, {"chord_m", 4.0 - k}, {"camber_pct", camber + k}, {"draft_pct", 40.0 + k},
                                 {"twist_deg", 10.0 + 5 * k}, {"entry_deg", 30.0 + 0.1 * k}, {"exit_deg", nullptr},
                                 {"uncertainty", {{"camber_pct", 0.2}}}, {"curve", {{0.0, 0.0, f}, {1.0, 0.1, f}}}});
    }
    const fs::path p = dir_ / (name + ".json");
    std::ofstream(p) << doc.dump();
    return p.string();
  }

  // Every kind of answer `db` gives on `db`, concatenated; failed commands are added to `failures`.
  std::string answers(const std::string& db, std::string* failures);

  fs::path dir_;
  std::string pg_;
};


TEST_F(DbCopyCli, QueriesAnswerByteIdenticallyOnAServerAndOnItsCopyToSQLiteAndBack) {
  ASSERT_EQ(run("db init " + pg_).exit_code, 0);
  for (int step = 0; step < 3; ++step) {
    const Outcome o = run("db import " + pg_ + " " + analysisJson(8 + step, "g1-" + std::to_string(step)) +
                          " --campaign Lorient --boat Alpha --sail G1 --sail-type genoa --test sweep --trim-step " +
                          std::to_string(step) + " --awa " + std::to_string(90 + 5 * step) + " --drive " +
                          std::to_string(100 + 20 * step) + " --side 50 --set sheet=0." + std::to_string(step) +
                          " --set traveller=-0.25 --pressure p1=12." + std::to_string(step));
    ASSERT_EQ(o.exit_code, 0) << o.err;
  }
  // A cloud as well: its blob must come through both copies.
  {
    std::ofstream xyz(dir_ / "g2.xyz");
    for (int i = 0; i < 500; ++i) xyz << i * 0.01 << " " << 0.001 * (i % 7) << " " << 1.0 + 0.002 * (i % 5) << "\n";
  }
  ASSERT_EQ(run("db import " + pg_ + " " + analysisJson(20, "g2") + " --cloud " + (dir_ / "g2.xyz").string() +
                " --campaign Lorient --sail G2 --sail-type genoa --test t2 --awa 94 --drive 140 --side 30")
                .exit_code,
            0);

  const std::string lite = (dir_ / "copy.db").string();
  const Outcome to_lite = run("db copy " + pg_ + " " + lite);
  ASSERT_EQ(to_lite.exit_code, 0) << to_lite.err;
  EXPECT_NE(to_lite.out.find("4 scans, 4 analyses, 12 sections"), std::string::npos) << to_lite.out;
  const std::string pg2 = sailshape::test::PgCluster::shared().createDatabase();  // empty: copy makes the schema
  const Outcome back = run("db copy " + lite + " " + pg2);
  ASSERT_EQ(back.exit_code, 0) << back.err;

  std::string failures;
  const std::string expected = answers(pg_, &failures);
  EXPECT_TRUE(failures.empty()) << failures;
  EXPECT_GT(expected.size(), 4000u);
  EXPECT_EQ(answers(lite, &failures), expected);
  EXPECT_EQ(answers(pg2, &failures), expected);
  EXPECT_TRUE(failures.empty()) << failures;
  for (const std::string& db : {pg_, lite, pg2}) {
    const Outcome check = run("db check " + db);
    EXPECT_EQ(check.exit_code, 0) << check.err;
    EXPECT_NE(check.out.find(": ok (schema version"), std::string::npos) << check.out;
  }
  // The stored cloud comes back from the copy as it went in.
  ASSERT_EQ(run("db show " + pg2 + " 4 --cloud " + (dir_ / "back.xyz").string()).exit_code, 0);
  EXPECT_NE(run("db show " + lite + " 4 --cloud " + (dir_ / "lite.xyz").string()).err.find("500 points"), std::string::npos);

  // A destination that holds rows is refused, unchanged; --append adds to it.
  const Outcome refused = run("db copy " + lite + " " + pg_);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("is not empty (1 campaigns, 1 boats, 2 sails"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("; --append adds to it"), std::string::npos) << refused.err;
  EXPECT_EQ(answers(pg_, &failures), expected);
  const Outcome appended = run("db copy " + lite + " " + pg_ + " --append");
  ASSERT_EQ(appended.exit_code, 0) << appended.err;
  const Outcome list = run("db list " + pg_ + " --csv");
  EXPECT_EQ(std::count(list.out.begin(), list.out.end(), '\n'), 1 + 8) << list.out;  // header, 4 + 4 scans
}

TEST_F(DbCopyCli, AnEmptyOrForeignServerDatabaseIsNamedInOneLine) {
  const Outcome empty = run("db check " + pg_);
  EXPECT_NE(empty.exit_code, 0);
  EXPECT_NE(empty.err.find("not a sailshape database (a PostgreSQL database without tables"), std::string::npos)
      << empty.err;
  EXPECT_EQ(std::count(empty.err.begin(), empty.err.end(), '\n'), 1) << empty.err;
  const std::string missing = "postgresql://postgres@127.0.0.1:" +
                              std::to_string(sailshape::test::PgCluster::shared().port()) + "/no_such_db";
  const Outcome gone = run("db list " + missing);
  EXPECT_NE(gone.exit_code, 0);
  EXPECT_NE(gone.err.find("cannot connect"), std::string::npos) << gone.err;
  EXPECT_EQ(std::count(gone.err.begin(), gone.err.end(), '\n'), 1) << gone.err;
  // Nothing of a failed copy into a new file stays behind.
  const Outcome failed = run("db copy " + missing + " " + (dir_ / "new.db").string());
  EXPECT_NE(failed.exit_code, 0);
  EXPECT_FALSE(fs::exists(dir_ / "new.db"));
}

std::string DbCopyCli::answers(const std::string& db, std::string* failures) {
  std::string all;
  for (const std::string& q :
       {std::string("db list "), std::string("db list --json "), std::string("db query --sections --csv "),
        std::string("db query --json "), std::string("db query --sail-type genoa --control sheet --control-min 0.1 "),
        std::string("db query --test sweep --evolution camber_pct --fraction 0.45 --csv "),
        std::string("db query --test sweep --evolution entry_deg --json "),
        std::string("db query --best drive --awa-min 80 --awa-max 120 --limit 3 --csv "),
        std::string("db query --best drive-side --awa-min 80 --awa-max 120 --limit 4 "),
        std::string("db query --compare G1,G2 --at-awa 95 --json "), std::string("db show 2 --json "),
        std::string("db show 4 ")}) {
    const std::string cmd = q.substr(0, q.find(' ', 3) + 1) + db + " " + q.substr(q.find(' ', 3) + 1);
    const Outcome o = run(cmd);
    if (o.exit_code != 0) *failures += cmd + ": " + o.err;
    all += "$ " + q + "\n" + o.out;
  }
  return all;
}

}  // namespace
