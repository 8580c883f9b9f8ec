// The README's "Your own data" block, run word for word as a new user would, and
// the bad inputs of its commands (db design, crop, analyze --design, db import).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "database/schema.hpp"
#include "database/scan_record.hpp"
#include "database/sqlite.hpp"
#include "tests/cli/run_sailshape.hpp"

namespace {

namespace fs = std::filesystem;
using sailshape::testing::Outcome;
using sailshape::testing::readText;

// SPEC §3: the LMS511's 1σ range noise, as `simulate` draws it.
constexpr double kSensorSigmaM = 0.004;

// The fenced block under the README's "## Your own data", one command a line.
std::vector<std::string> readmeBlock() {
  const std::string readme = readText(SAILSHAPE_README);
  const size_t heading = readme.find("\n## Your own data\n");
  EXPECT_NE(heading, std::string::npos) << "README.md has no \"Your own data\" section";
  if (heading == std::string::npos) return {};
  const size_t open = readme.find("\n```\n", heading);
  const size_t close = readme.find("\n```\n", open + 5);
  std::vector<std::string> lines;
  std::istringstream in(readme.substr(open + 5, close - open - 5));
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

std::vector<std::string> nonEmptyLines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find_first_not_of(" \r\t") != std::string::npos) out.push_back(line);
  return out;
}

int64_t scalar(sailshape::Database& db, const std::string& sql) {
  sailshape::Statement s = db.prepare(sql);
  s.step();
  return s.isNull(0) ? -1 : s.columnInt(0);
}

class OwnData : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sailshape_own_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // `sailshape ARGS` run in the test's folder, as a user types it there.
  Outcome sailshape(const std::string& args) {
    const int code = shell("'" + std::string(SAILSHAPE_BIN) + "' " + args);
    return {code, readText(dir_ / "out.txt"), readText(dir_ / "err.txt")};
  }
  // Runs `line` in the test's folder as a shell would; stdout and stderr in out.txt and err.txt.
  int shell(const std::string& line) {
    const std::string cmd = "cd '" + dir_.string() + "' && " + line + " >out.txt 2>err.txt </dev/null";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // A bad input: exit 1 and one line on stderr that names `word`.
  void expectOneLineError(const Outcome& o, const std::string& word) {
    EXPECT_EQ(o.exit_code, 1) << o.err;
    const std::vector<std::string> lines = nonEmptyLines(o.err);
    ASSERT_EQ(lines.size(), 1u) << o.err;
    EXPECT_NE(lines[0].find(word), std::string::npos) << lines[0];
    EXPECT_EQ(lines[0].find("[", lines[0].find("error:")), std::string::npos) << "internal name leaked: " << lines[0];
  }
  fs::path dir_;
};

// The README's block from db init to the viewer, with the binaries where the README
// names them (build/cli, build/viewer) and the viewer's window shot under Xvfb.
TEST_F(OwnData, TheReadmesBlockRunsWordForWordAndStoresTheSailOnItsDesign) {
  const std::vector<std::string> block = readmeBlock();
  ASSERT_EQ(block.size(), 7u);
  const std::vector<std::string> order = {"design new", "simulate", "db init", "db design add", "db import", "report"};
  for (size_t i = 0; i < order.size(); ++i)
    EXPECT_EQ(block[i].rfind("build/cli/sailshape " + order[i], 0), 0u) << block[i];
  EXPECT_EQ(block[6].rfind("build/viewer/sailshape-viewer ", 0), 0u) << block[6];
  fs::create_directories(dir_ / "build/cli");
  fs::create_directories(dir_ / "build/viewer");
  fs::create_symlink(SAILSHAPE_BIN, dir_ / "build/cli/sailshape");
#if defined(SAILSHAPE_VIEWER_BIN)
  fs::create_symlink(SAILSHAPE_VIEWER_BIN, dir_ / "build/viewer/sailshape-viewer");
  const bool viewer_built = true;
#elif defined(SAILSHAPE_SANITIZER_TREE_WITHOUT_VIEWER)
  const bool viewer_built = false;  // the Release tree's run of this test opens the viewer
#else
  const bool viewer_built = false;
  ADD_FAILURE() << "the README's block ends in the viewer, which this build does not have";
#endif
  for (size_t i = 0; i + 1 < block.size(); ++i)
    ASSERT_EQ(shell(block[i]), 0) << block[i] << "\n" << readText(dir_ / "err.txt");
  EXPECT_EQ(readText(dir_ / "err.txt").find("warning"), std::string::npos)
      << "the report of a sail on its own design warns:\n" << readText(dir_ / "err.txt");
  {
    sailshape::Database db = sailshape::openSailDatabase((dir_ / "my.db").string());
    EXPECT_EQ(scalar(db, "SELECT count(*) FROM design_versions"), 1);
    EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans"), 1);
    // The simulated sail is its design plus 4 mm noise (smoothed): its points lie
    // on the design within the noise.
    sailshape::Statement c = db.prepare("SELECT mean_m, rms_m FROM design_comparisons");
    ASSERT_TRUE(c.step()) << "the import stored no design comparison";
    EXPECT_LT(std::abs(c.columnDouble(0)), kSensorSigmaM);
    EXPECT_LT(c.columnDouble(1), 3 * kSensorSigmaM);
    const sailshape::ScanRecord record = sailshape::loadScanRecord(db, 1);
    ASSERT_TRUE(record.region.has_value()) << "the scan was stored without its region";
    EXPECT_EQ(record.region->design_version, 1);
    // The example main stands from its tack at z = 1 m to its head near 11 m; the region holds it, not the deck.
    EXPECT_LT(record.region->box.min().z(), 1.0);
    EXPECT_GT(record.region->box.max().z(), 10.9);
  }
  ASSERT_EQ(shell("pdftotext my-main.pdf my-main.txt"), 0);
  EXPECT_NE(readText(dir_ / "my-main.txt").find("My main"), std::string::npos);
  // The viewer, as the README opens it, shows the stored scan: its window shot under a private X server.
  if (!viewer_built) return;
  const std::string viewer = block[6] + " --screenshot shot.png --frames 5";
  ASSERT_EQ(shell("xvfb-run -a -s '-screen 0 1600x1000x24' " + viewer), 0) << readText(dir_ / "err.txt");
  EXPECT_GT(fs::file_size(dir_ / "shot.png"), 10'000u);
}

// Versions count up and the current one is what export writes by default.
TEST_F(OwnData, DesignVersionsAreListedShownAndExported) {
  ASSERT_EQ(sailshape("design new --type main --out d1.obj").exit_code, 0);
  ASSERT_EQ(sailshape("design new --type main --luff 11 --out d2.stl").exit_code, 0);
  ASSERT_EQ(sailshape("db init v.db").exit_code, 0);
  ASSERT_EQ(sailshape("db design add v.db --sail M d1.obj").exit_code, 0);
  const Outcome second = sailshape("db design add v.db --sail M d2.stl");
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_NE(second.out.find("design version 2"), std::string::npos) << second.out;
  const Outcome list = sailshape("db design list v.db --sail M");
  ASSERT_EQ(list.exit_code, 0);
  EXPECT_NE(list.out.find("2 *"), std::string::npos) << list.out;
  const Outcome show = sailshape("db design show v.db --sail M --json cur.json");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const nlohmann::json cur = nlohmann::json::parse(readText(dir_ / "cur.json"));
  // design new's --luff is the straight tack-to-head length.
  EXPECT_NEAR(cur["sail"]["luff_straight_m"].get<double>(), 11.0, 0.01);
  ASSERT_EQ(sailshape("db design show v.db --sail M --version 1 --json v1.json").exit_code, 0);
  EXPECT_NEAR(nlohmann::json::parse(readText(dir_ / "v1.json"))["sail"]["luff_straight_m"].get<double>(), 10.0, 0.01);
  ASSERT_EQ(sailshape("db design export v.db --sail M --version 1 back.obj").exit_code, 0);
  ASSERT_EQ(sailshape("design show back.obj --json back.json").exit_code, 0);
  EXPECT_NEAR(nlohmann::json::parse(readText(dir_ / "back.json"))["sail"]["luff_straight_m"].get<double>(), 10.0, 0.01);
}

// Every bad input is one line naming the problem, and stores or writes nothing.
TEST_F(OwnData, BadInputsAreOneLineAndStoreNothing) {
  ASSERT_EQ(sailshape("db init b.db").exit_code, 0);
  ASSERT_EQ(sailshape("simulate --type main --scene --points 20000 --out scan.ply").exit_code, 0);
  std::ofstream(dir_ / "garbage.obj") << "this is no mesh\nv 1 2\nf 1 2 9\n";
  std::ofstream(dir_ / "notes.txt") << "a design?\n";
  expectOneLineError(sailshape("db design add b.db --sail M missing.obj"), "missing.obj");
  expectOneLineError(sailshape("db design add b.db --sail M garbage.obj"), "garbage.obj");
  expectOneLineError(sailshape("db design add b.db --sail M scan.ply"), "scan.ply");  // a cloud, not a mesh
  expectOneLineError(sailshape("db design add b.db --sail M notes.txt"), "notes.txt");
  expectOneLineError(sailshape("db design list b.db --sail Nope"), "Nope");
  expectOneLineError(sailshape("db design show b.db --sail Nope"), "Nope");
  expectOneLineError(sailshape("db design export b.db --sail Nope out.obj"), "Nope");
  EXPECT_FALSE(fs::exists(dir_ / "out.obj"));
  {
    sailshape::Database db = sailshape::openSailDatabase((dir_ / "b.db").string());
    EXPECT_EQ(scalar(db, "SELECT count(*) FROM sails"), 0) << "a refused design created its sail";
    EXPECT_EQ(scalar(db, "SELECT count(*) FROM design_versions"), 0);
  }
  expectOneLineError(sailshape("crop scan.ply --box 1,0,0,1,0,12 --out c.ply"), "xmin");
  expectOneLineError(sailshape("crop scan.ply --box 0,1,nan,1,0,12 --out c.ply"), "nan");
  expectOneLineError(sailshape("crop scan.ply --box 0,1,0,1,0 --out c.ply"), "six numbers");
  expectOneLineError(sailshape("crop scan.ply --box 50,51,0,1,0,1 --out c.ply"), "region");
  expectOneLineError(sailshape("crop scan.ply --design scan.ply --out c.ply"), "scan.ply");
  ASSERT_EQ(sailshape("design new --type main --out main.obj").exit_code, 0);
  expectOneLineError(sailshape("crop scan.ply --design main.obj --margin nan --out c.ply"), "margin");
  expectOneLineError(sailshape("crop scan.ply --design main.obj --margin -1 --out c.ply"), "margin");
  EXPECT_FALSE(fs::exists(dir_ / "c.ply"));
  // A scan that does not hold the sail (the main's design 30 m aft of it) stores nothing.
  ASSERT_EQ(sailshape("design new --type main --tack -30,0,1 --out far.obj").exit_code, 0);
  ASSERT_EQ(sailshape("db design add b.db --sail Far far.obj").exit_code, 0);
  const Outcome none = sailshape("db import b.db scan.ply --sail Far");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("nothing stored"), std::string::npos) << none.err;
  sailshape::Database db = sailshape::openSailDatabase((dir_ / "b.db").string());
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM scans"), 0);
  EXPECT_EQ(scalar(db, "SELECT count(*) FROM trim_steps"), 0);
}

// The check that the analysis found its sail: a main analysed against the design of
// a main 20 % larger (its tack where this one's is, so the pick still finds it) is one
// warning line (area 70 % of the design's, beyond ±20 %; each edge 83 %, beyond
// ±10 %); against its own, none.
TEST_F(OwnData, ASailFarFromItsDesignIsAWarning) {
  ASSERT_EQ(sailshape("simulate --type main --points 30000 --out main.ply").exit_code, 0);
  ASSERT_EQ(sailshape("design new --type main --out main.obj").exit_code, 0);
  ASSERT_EQ(sailshape("design new --type main --luff 12 --leech 12.6 --foot 4.3 --out big.obj").exit_code, 0);
  const Outcome own = sailshape("analyze main.ply --design main.obj -q --json own.json");
  ASSERT_EQ(own.exit_code, 0) << own.err;
  EXPECT_EQ(own.err.find("warning: the analysed surface"), std::string::npos) << own.err;
  EXPECT_EQ(nlohmann::json::parse(readText(dir_ / "own.json"))["design"]["mismatch"], "");
  // Imported with its cloud, the analysis keeps the region it was cropped to.
  ASSERT_EQ(sailshape("db init j.db").exit_code, 0);
  ASSERT_EQ(sailshape("db import j.db own.json --cloud main.ply --sail M").exit_code, 0);
  {
    sailshape::Database db = sailshape::openSailDatabase((dir_ / "j.db").string());
    const sailshape::ScanRecord record = sailshape::loadScanRecord(db, 1);
    ASSERT_TRUE(record.region.has_value());
    EXPECT_LT(record.region->box.min().z(), 1.0);  // the example main's tack stands at z = 1 m
  }
  const Outcome other = sailshape("analyze main.ply --design big.obj -q --json other.json");
  ASSERT_EQ(other.exit_code, 0) << other.err;
  size_t warnings = 0;
  for (const std::string& line : nonEmptyLines(other.err))
    warnings += line.find("does not fly like this sail's design") != std::string::npos ? 1 : 0;
  EXPECT_EQ(warnings, 1u) << other.err;
  const nlohmann::json doc = nlohmann::json::parse(readText(dir_ / "other.json"));
  const std::string mismatch = doc["design"]["mismatch"].get<std::string>();
  EXPECT_NE(mismatch.find("area 70 %"), std::string::npos) << mismatch;
  EXPECT_NE(mismatch.find("luff 83 %"), std::string::npos) << mismatch;
}

}  // namespace
