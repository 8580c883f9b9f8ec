// Runs `sailshape db` as a user would: exit codes, one-line errors, files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "database/sqlite.hpp"
#include "tests/cli/run_sailshape.hpp"

namespace {

namespace fs = std::filesystem;

using sailshape::testing::Outcome;
using sailshape::testing::readText;

class DbCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sailshape-dbcli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    db_ = (dir_ / "t.db").string();
  }
  void TearDown() override {
    std::error_code ec;  // a folder a test made read-only must be writable again to be removed
    fs::permissions(dir_ / "locked", fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_);
  }

  Outcome run(const std::string& args) { return sailshape::testing::runSailshape(dir_, args); }

  // As run(), but as user nobody when the tests run as root: file modes do not
  // stop root, and the read-only cases are about users they do stop.
  Outcome runUnprivileged(const std::string& args) {
    if (::geteuid() != 0) return run(args);
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string("setpriv --reuid=65534 --regid=65534 --clear-groups '") + SAILSHAPE_BIN + "' " +
                            args + " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readText(out), readText(err)};
  }

  // Files SQLite keeps beside a database while it is open (-wal, -shm, -journal).
  std::vector<std::string> sideFiles(const fs::path& folder) {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(folder)) {
      const std::string name = e.path().filename().string();
      for (const char* tail : {"-wal", "-shm", "-journal"})
        if (name.size() > std::strlen(tail) && name.compare(name.size() - std::strlen(tail), std::string::npos, tail) == 0)
          found.push_back(name);
    }
    return found;
  }

  std::string analysisJson(double camber) {
    nlohmann::json doc;
    doc["sections"] = nlohmann::json::array();
    for (int k = 0; k < 3; ++k)
      doc["sections"].push_back({{"fraction", 0.25 * (k + 1)}, {"camber_pct", camber + k}, {"draft_pct", 42.0},
                                 {"uncertainty", {{"camber_pct", 0.3}}}, {"curve", {{0, 0, 1}, {1, 0.1, 1}}}});
    const fs::path p = dir_ / ("a" + std::to_string(int(camber)) + ".json");
    std::ofstream(p) << doc.dump();
    return p.string();
  }

  fs::path dir_;
  std::string db_;
};

int countLines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

TEST_F(DbCli, InitImportQueryExportCheckBackup) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  for (int step = 0; step < 3; ++step) {
    const Outcome o = run("db import " + db_ + " " + analysisJson(8 + step) + " --campaign Lorient --sail G1 --sail-type genoa" +
                          " --test sweep --trim-step " + std::to_string(step) + " --awa " + std::to_string(90 + 5 * step) +
                          " --drive " + std::to_string(100 + 20 * step) + " --side 50 --set sheet=0." + std::to_string(step));
    ASSERT_EQ(o.exit_code, 0) << o.err;
    EXPECT_NE(o.out.find("3 sections"), std::string::npos) << o.out;
  }
  Outcome list = run("db list " + db_ + " --csv");
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_EQ(countLines(list.out), 4);  // header + 3 scans

  Outcome evo = run("db query " + db_ + " --evolution camber_pct --test sweep --fraction 0.5 --json");
  ASSERT_EQ(evo.exit_code, 0) << evo.err;
  const auto j = nlohmann::json::parse(evo.out);
  ASSERT_EQ(j.size(), 3u);
  EXPECT_DOUBLE_EQ(j[2]["value"].get<double>(), 11.0);

  Outcome best = run("db query " + db_ + " --best drive --awa-min 85 --awa-max 100 --csv");
  ASSERT_EQ(best.exit_code, 0) << best.err;
  EXPECT_NE(best.out.find(",G1,sweep,2,100,140,50,"), std::string::npos) << best.out;

  const std::string csv = (dir_ / "sections.csv").string();
  ASSERT_EQ(run("db export " + db_ + " " + csv + " --sections --awa-min 94 --awa-max 96").exit_code, 0);
  EXPECT_EQ(countLines(readText(csv)), 4);  // header + the 3 sections at 95°

  Outcome show = run("db show " + db_ + " 2");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  EXPECT_NE(show.out.find("sheet=0.1"), std::string::npos) << show.out;
  EXPECT_NE(run("db show " + db_ + " 99").exit_code, 0);

  EXPECT_EQ(run("db check " + db_).exit_code, 0);
  const std::string copy = (dir_ / "copy.db").string();
  ASSERT_EQ(run("db backup " + db_ + " " + copy).exit_code, 0);
  EXPECT_EQ(run("db check " + copy).exit_code, 0);
  EXPECT_EQ(run("db list " + copy + " --csv").out, list.out);
}

TEST_F(DbCli, ShowNamesTheSectionsTheAnalysisCouldNotMeasure) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  nlohmann::json doc = nlohmann::json::parse(readText(analysisJson(9)));
  doc["sections"].erase(1);  // 0.5 was asked for and not measured
  const std::string why = "the section plane at fraction 0.500 crosses a hole 44 % of the chord wide (bridged up to 35 %)";
  doc["unmeasured_sections"] = {{{"fraction", 0.5}, {"reason", why}}};
  const fs::path file = dir_ / "partial.json";
  std::ofstream(file) << doc.dump();
  const Outcome o = run("db import " + db_ + " " + file.string() + " --sail G1");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("2 sections"), std::string::npos) << o.out;

  Outcome show = run("db show " + db_ + " 1");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  EXPECT_NE(show.out.find("section 0.500 not measured: " + why), std::string::npos) << show.out;
  show = run("db show " + db_ + " 1 --json");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const auto j = nlohmann::json::parse(show.out);
  EXPECT_EQ(j["sections"].size(), 2u);
  ASSERT_EQ(j["unmeasured_sections"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["unmeasured_sections"][0]["fraction"].get<double>(), 0.5);
  EXPECT_EQ(j["unmeasured_sections"][0]["reason"].get<std::string>(), why);
}

TEST_F(DbCli, ShowWritesTheStoredCloudBackWithItsAnglesAndViewpoint) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  const fs::path in = dir_ / "scan.ply";
  {
    std::ofstream f(in);
    f << "ply\nformat ascii 1.0\ncomment viewpoint -8 -9.5 5.25\nelement vertex 3\n"
         "property double x\nproperty double y\nproperty double z\n"
         "property double alpha_rad\nproperty double beta_rad\nend_header\n"
         "1 2 3 0.5 1.5\n4 5 6 0.25 1.75\n7 8 9 -0.125 2\n";
  }
  ASSERT_EQ(run("db import " + db_ + " " + in.string() + " --sail G1").exit_code, 0);
  const std::string out = (dir_ / "back.xyz").string();
  const Outcome show = run("db show " + db_ + " 1 --cloud " + out);
  ASSERT_EQ(show.exit_code, 0) << show.err;
  EXPECT_NE(show.err.find("wrote the stored cloud of scan 1 (3 points) to " + out), std::string::npos) << show.err;
  // Read back by the same reader `analyze` uses: the points (float32 in the
  // database), their angles and the viewpoint as imported.
  const Outcome again = run("db import " + db_ + " " + out + " --sail G1 --trim-step 2");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const std::string twice = (dir_ / "twice.ply").string();
  ASSERT_EQ(run("db show " + db_ + " 2 --cloud " + twice).exit_code, 0);
  const std::string text = readText(out);
  EXPECT_NE(text.find("viewpoint -8 -9.5 5.25"), std::string::npos) << text;
  EXPECT_NE(text.find("alpha_rad"), std::string::npos) << text;
  EXPECT_NE(text.find("\n7 8 9 -0.125 2"), std::string::npos) << text;
  const std::string ply = readText(twice);
  EXPECT_NE(ply.find("comment viewpoint -8 -9.5 5.25"), std::string::npos);
  EXPECT_NE(ply.find("property double beta_rad"), std::string::npos);
  EXPECT_NE(ply.find("element vertex 3"), std::string::npos);

  // A scan stored from its analysis alone has no cloud to write.
  ASSERT_EQ(run("db import " + db_ + " " + analysisJson(8) + " --sail G1 --trim-step 3").exit_code, 0);
  const Outcome none = run("db show " + db_ + " 3 --cloud " + (dir_ / "none.ply").string());
  EXPECT_NE(none.exit_code, 0);
  EXPECT_EQ(countLines(none.err), 1) << none.err;
  EXPECT_NE(none.err.find("db show: scan 3 has no stored cloud (only its analysis was imported)"), std::string::npos)
      << none.err;
  EXPECT_FALSE(fs::exists(dir_ / "none.ply"));
}

TEST_F(DbCli, ErrorsAreOneLineAndNonZero) {
  const std::string notes = (dir_ / "notes.db").string();
  std::ofstream(notes) << "not a database, just a long enough line of text to fill a header\n";
  const std::string before = readText(notes);
  for (const std::string& args : {"db check " + notes, "db init " + notes, "db list " + notes,
                                  "db list " + (dir_ / "missing.db").string()}) {
    const Outcome o = run(args);
    EXPECT_NE(o.exit_code, 0) << args;
    EXPECT_EQ(countLines(o.err), 1) << args << ": " << o.err;
  }
  EXPECT_EQ(readText(notes), before);
  EXPECT_FALSE(fs::exists(dir_ / "missing.db"));

  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  const Outcome bad_set = run("db import " + db_ + " " + analysisJson(8) + " --set sheet=abc");
  EXPECT_NE(bad_set.exit_code, 0);
  EXPECT_NE(bad_set.err.find("--set sheet needs a number"), std::string::npos) << bad_set.err;
  const Outcome no_format = run("db export " + db_ + " " + (dir_ / "out.txt").string());
  EXPECT_NE(no_format.exit_code, 0);
  EXPECT_NE(no_format.err.find("--csv or --json"), std::string::npos) << no_format.err;
  EXPECT_NE(run("db query " + db_ + " --evolution camber_pct").exit_code, 0);  // needs --test
}

TEST_F(DbCli, CheckSaysInOneLineWhenTheFileIsNotOurs) {
  const std::string empty = (dir_ / "empty.db").string();
  std::ofstream{empty};
  Outcome o = run("db check " + empty);
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: db check: " + empty + ": not a sailshape database (empty file)\n");
  EXPECT_EQ(fs::file_size(empty), 0u);

  const std::string foreign = (dir_ / "foreign.db").string();
  {
    sailshape::Database other(foreign);
    other.exec("CREATE TABLE notes(id INTEGER PRIMARY KEY, body TEXT); CREATE TABLE tags(name TEXT)");
  }
  o = run("db check " + foreign);
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: db check: " + foreign +
                       ": not a sailshape database (an SQLite database of another application: 2 tables, no sailshape "
                       "schema)\n");
}

TEST_F(DbCli, CheckOfADamagedFileIsOneLineAndListsOnlyWithVerbose) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  for (int step = 0; step < 3; ++step)
    ASSERT_EQ(run("db import " + db_ + " " + analysisJson(8 + step) + " --trim-step " + std::to_string(step)).exit_code, 0);
  int64_t root_page = 0, page_size = 0;
  {
    sailshape::Database d(db_);
    sailshape::Statement s = d.prepare("SELECT rootpage FROM sqlite_schema WHERE name = 'sections_analysis'");
    ASSERT_TRUE(s.step());
    root_page = s.columnInt(0);
    sailshape::Statement p = d.prepare("PRAGMA page_size");
    p.step();
    page_size = p.columnInt(0);
  }
  // Bytes overwritten in the middle of the file: the index of the 9 section rows
  // becomes an empty leaf page (type 0x0a, no cells), so every row misses from it.
  {
    std::fstream f(db_, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp((root_page - 1) * page_size);
    std::string page(static_cast<size_t>(page_size), '\0');
    page[0] = 0x0a;
    page[5] = static_cast<char>(page_size >> 8);
    page[6] = static_cast<char>(page_size & 0xff);
    f.write(page.data(), static_cast<std::streamsize>(page.size()));
  }
  Outcome o = run("db check " + db_);
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: db check: " + db_ +
                       ": damaged: 10 integrity problems, first: row 1 missing from index sections_analysis (--verbose "
                       "lists them)\n");
  o = run("db check " + db_ + " --verbose");
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(countLines(o.err), 11) << o.err;  // ten problems listed, then the one line
  EXPECT_EQ(o.err.rfind("  row 1 missing from index sections_analysis\n", 0), 0u) << o.err;
  EXPECT_NE(o.err.find("wrong # of entries in index sections_analysis"), std::string::npos) << o.err;
}

TEST_F(DbCli, ReadingAReadOnlyDatabaseLeavesNothingBehind) {
  if (::geteuid() == 0 && std::system("command -v setpriv >/dev/null") != 0) GTEST_SKIP() << "root without setpriv";
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  ASSERT_EQ(run("db import " + db_ + " " + analysisJson(8) + " --sail G1").exit_code, 0);
  ASSERT_TRUE(sideFiles(dir_).empty());
  const std::string before = readText(db_);

  // Mode 0444 in a folder the reader may write.
  fs::permissions(db_, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(dir_, fs::perms::all);
  Outcome o = runUnprivileged("db query " + db_ + " --sections --csv");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_EQ(countLines(o.out), 4);  // header + 3 sections
  o = runUnprivileged("db show " + db_ + " 1");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("G1"), std::string::npos) << o.out;
  EXPECT_EQ(sideFiles(dir_), std::vector<std::string>{});
  EXPECT_EQ(readText(db_), before);

  // A writable file in a folder the reader may not write.
  const fs::path locked = dir_ / "locked";
  fs::create_directories(locked);
  const std::string inside = (locked / "t.db").string();
  fs::copy_file(db_, inside);
  fs::permissions(inside, fs::perms::all);
  fs::permissions(locked, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                              fs::perms::others_exec);
  if (::geteuid() != 0) fs::permissions(locked, fs::perms::owner_write, fs::perm_options::remove);
  o = runUnprivileged("db list " + inside + " --csv");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_EQ(countLines(o.out), 2);  // header + 1 scan
  EXPECT_EQ(sideFiles(locked), std::vector<std::string>{});
}

TEST_F(DbCli, ImportIntoAMissingFileSaysToInitItAndCreatesNothing) {
  const std::string missing = (dir_ / "missing.db").string();
  const Outcome o = run("db import " + missing + " " + analysisJson(8));
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: db import: " + missing + " does not exist; run `sailshape db init " + missing +
                       "` first\n");
  EXPECT_FALSE(fs::exists(missing));
}

TEST_F(DbCli, ImportNamesTheTrimStepAsGivenAndItsIdAsAnId) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  ASSERT_EQ(run("db import " + db_ + " " + analysisJson(8) + " --test sweep --trim-step 0").exit_code, 0);
  ASSERT_EQ(run("db import " + db_ + " " + analysisJson(8) + " --test reach --trim-step 0").exit_code, 0);
  Outcome o = run("db import " + db_ + " " + analysisJson(9) + " --test sweep --trim-step 1");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_EQ(o.out, "imported scan 3 (trim step 1 of test \"sweep\", trim step id 3, 3 sections)\n");
  o = run("db import " + db_ + " " + analysisJson(10) + " --trim-step 1");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  EXPECT_EQ(o.out, "imported scan 4 (trim step 1, trim step id 4, 3 sections)\n");
}

TEST_F(DbCli, WrongTypedValueRefusesTheImportNamingFieldAndSection) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  nlohmann::json doc = nlohmann::json::parse(readText(analysisJson(8)));
  doc["sections"][1]["camber_pct"] = "lots";
  const fs::path file = dir_ / "typo.json";
  std::ofstream(file) << doc.dump();
  Outcome o = run("db import " + db_ + " " + file.string());
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: section 0.500: camber_pct must be a number or null (got \"lots\")\n");
  o = run("db list " + db_ + " --csv");
  EXPECT_EQ(countLines(o.out), 1) << o.out;  // the header only: nothing stored

  doc["sections"][1]["camber_pct"] = 9.0;
  doc["sections"][2]["uncertainty"]["draft_pct"] = {1.0};
  std::ofstream(file, std::ios::trunc) << doc.dump();
  o = run("db import " + db_ + " " + file.string());
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: section 0.750 uncertainty: draft_pct must be a number or null (got [1.0])\n");

  // null means "not measured" and stays allowed.
  doc["sections"][2]["uncertainty"]["draft_pct"] = nullptr;
  doc["sections"][2]["camber_pct"] = nullptr;
  std::ofstream(file, std::ios::trunc) << doc.dump();
  o = run("db import " + db_ + " " + file.string());
  ASSERT_EQ(o.exit_code, 0) << o.err;
  o = run("db query " + db_ + " --sections --json");
  ASSERT_EQ(o.exit_code, 0) << o.err;
  const auto rows = nlohmann::json::parse(o.out);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_DOUBLE_EQ(rows[1]["camber_pct"].get<double>(), 9.0);
  EXPECT_TRUE(rows[2]["camber_pct"].is_null()) << rows[2].dump();
}

// An analysis of a cloud scaled by 1e30 (a 62-digit area) is no sail's: refused with
// its field named, nothing stored.
TEST_F(DbCli, ASailNoScanCouldMeasureIsRefused) {
  ASSERT_EQ(run("db init " + db_).exit_code, 0);
  nlohmann::json doc = nlohmann::json::parse(readText(analysisJson(8)));
  doc["sail"]["area_m2"] = 3.7e62;
  const fs::path file = dir_ / "huge.json";
  std::ofstream(file) << doc.dump();
  Outcome o = run("db import " + db_ + " " + file.string());
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err.rfind("sailshape: error: sail.area_m2 of 3.7e+62 m² is no sail's", 0), 0u) << o.err;
  EXPECT_EQ(countLines(o.err), 1) << o.err;
  doc["sail"]["area_m2"] = 20.0;
  doc["sail"]["luff_length_m"] = 12400.0;  // millimetres
  std::ofstream(file, std::ios::trunc) << doc.dump();
  o = run("db import " + db_ + " " + file.string());
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err.rfind("sailshape: error: sail.luff_length_m of 12400.0 m is no sail's", 0), 0u) << o.err;
  o = run("db list " + db_ + " --csv");
  EXPECT_EQ(countLines(o.out), 1) << o.out;  // the header only
}

TEST_F(DbCli, ErrorsNameTheInternalFunctionOnlyWithVerbose) {
  const std::string notes = (dir_ / "notes.db").string();
  std::ofstream(notes) << "not a database, just a long enough line of text to fill a header\n";
  Outcome o = run("db list " + notes);
  EXPECT_NE(o.exit_code, 0);
  EXPECT_EQ(o.err, "sailshape: error: " + notes + ": not an SQLite database (or encrypted); left untouched\n");
  for (const std::string& args : {"--verbose db list " + notes, "db list " + notes + " --verbose"}) {
    o = run(args);
    EXPECT_NE(o.exit_code, 0) << args;
    EXPECT_EQ(o.err, "sailshape: error: [Database::exec] " + notes +
                         ": not an SQLite database (or encrypted); left untouched\n")
        << args;
  }
}

}  // namespace
