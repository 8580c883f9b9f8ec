// Runs the built `sailshape` command as a user would and checks its exit codes,
// its messages and the files it writes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/pipeline/params_io.hpp"
#include "tests/cli/run_sailshape.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using sailshape::testing::Outcome;
using sailshape::testing::readText;

// A fraction as the analysis's messages print it: "0.750".
std::string fixed3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) result.push_back(line);
  return result;
}

// A fresh temp directory per test; `sailshape` runs with stdout and stderr captured there.
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sailshape_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Outcome sailshape(const std::string& args) { return sailshape::testing::runSailshape(dir_, args); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

void expectMentions(const std::string& text, const std::vector<std::string>& words) {
  for (const auto& w : words) EXPECT_NE(text.find(w), std::string::npos) << "help lacks '" << w << "':\n" << text;
}

TEST_F(Cli, HelpListsTheSubcommands) {
  const Outcome r = sailshape("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"analyze", "simulate", "--help", "--version"});
}

// The names a help lists under "Subcommands:", one per line up to the blank line after them.
std::vector<std::string> subcommandsListed(const std::string& help) {
  std::vector<std::string> names;
  bool in_list = false;
  for (const std::string& line : lines(help)) {
    if (line == "Subcommands:") {
      in_list = true;
    } else if (in_list && line.empty()) {
      break;
    } else if (in_list) {
      std::istringstream words(line);
      std::string name;
      words >> name;
      names.push_back(name);
    }
  }
  return names;
}

// Every command reachable from `sailshape --help`, by its words after `sailshape`
// ("" for sailshape itself), with its help; `sailshape` runs in `dir`.
void collectHelps(const fs::path& dir, const std::string& path, std::vector<std::pair<std::string, std::string>>& out) {
  const Outcome r = sailshape::testing::runSailshape(dir, path + (path.empty() ? "" : " ") + "--help");
  ASSERT_EQ(r.exit_code, 0) << path << ": " << r.err;
  out.emplace_back(path, r.out);
  for (const std::string& name : subcommandsListed(r.out)) collectHelps(dir, path.empty() ? name : path + " " + name, out);
}

TEST_F(Cli, EveryCommandsHelpEndsWithExamplesOfItself) {
  std::vector<std::pair<std::string, std::string>> helps;
  collectHelps(dir_, "", helps);
  // sailshape, its 14 commands, design's 2, db's 10, db design's 4 and scanner's 1.
  ASSERT_EQ(helps.size(), 32u);
  for (const auto& [path, help] : helps) {
    const size_t examples = help.find("\nExamples:\n");
    ASSERT_NE(examples, std::string::npos) << "`sailshape " << path << " --help` has no examples:\n" << help;
    // Each example (a line "  sailshape ...", continued after a trailing backslash) runs this very command.
    int count = 0;
    for (const std::string& line : lines(help.substr(examples + 11))) {
      if (line.rfind("  sailshape", 0) != 0) continue;
      ++count;
      EXPECT_EQ(line.rfind("  sailshape " + path, 0), 0u) << "an example of `" << path << "` runs another command: " << line;
    }
    EXPECT_GE(count, 1) << path;
    EXPECT_LE(count, 2) << path;
  }
}

// The example command lines of a help, each whole (joined where a trailing backslash continues it).
std::vector<std::string> examplesOf(const std::string& help) {
  std::vector<std::string> out;
  const size_t at = help.find("\nExamples:\n");
  if (at == std::string::npos) return out;
  bool continued = false;
  for (const std::string& line : lines(help.substr(at + 11))) {
    const bool more = line.size() >= 2 && line.compare(line.size() - 2, 2, " \\") == 0;
    const std::string text = more ? line.substr(0, line.size() - 2) : line;
    if (continued)
      out.back() += " " + text.substr(text.find_first_not_of(' '));
    else if (text.rfind("  sailshape", 0) == 0)
      out.push_back(text.substr(2));
    continued = more;
  }
  return out;
}

// The examples of the commands that need no scanner or demo run, run as written in
// the order the help lists them, from a folder with the source tree's assets/:
// each works, on the files the ones before it wrote.
TEST_F(Cli, ExamplesRunAsWritten) {
  fs::create_directory_symlink(fs::path(SAILSHAPE_ASSETS), dir_ / "assets");
  const std::string bin_dir = fs::path(SAILSHAPE_BIN).parent_path().string();
  int ran = 0;
  for (const char* command : {"analyze", "simulate", "design", "design new", "design show", "compare", "fit", "db", "db init",
                              "db import", "db list", "db show", "db query", "db export", "db check", "db backup", "db copy",
                              "db design", "db design add", "db design list", "db design show", "db design export", "crop"}) {
    const Outcome help = sailshape(std::string(command) + " --help");
    for (const std::string& example : examplesOf(help.out)) {
      if (example.find("demo-output") != std::string::npos) continue;  // needs `sailshape demo` first
      const std::string cmd = "cd '" + dir_.string() + "' && PATH='" + bin_dir + "':\"$PATH\" " + example +
                              " >example-out.txt 2>example-err.txt </dev/null";
      const int status = std::system(cmd.c_str());
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
          << example << "\n" << readText(dir_ / "example-err.txt");
      ++ran;
    }
  }
  EXPECT_GE(ran, 25);
  EXPECT_TRUE(fs::exists(dir_ / "trials-backup.db"));
  EXPECT_TRUE(fs::exists(dir_ / "trials-copy.db"));
  EXPECT_TRUE(fs::exists(dir_ / "sections.csv"));
}

TEST_F(Cli, CommandListsHaveOneShortLinePerCommand) {
  const Outcome top = sailshape("--help");
  ASSERT_EQ(top.exit_code, 0) << top.err;
  for (const std::string& line : lines(top.out)) EXPECT_LE(line.size(), 120u) << line;
  EXPECT_EQ(subcommandsListed(top.out).size(), 14u) << top.out;  // with fit and crop

  // The details stay in the command's own help: analyze's tells of mixed pixels, its line in the list does not.
  const Outcome analyze = sailshape("analyze --help");
  EXPECT_NE(analyze.out.find("mixed pixels"), std::string::npos) << analyze.out;
  EXPECT_EQ(top.out.find("mixed pixels"), std::string::npos) << top.out;
  // Every list of subcommands (db's, design's, scanner's) keeps to a line each.
  for (const char* parent : {"db", "db design", "design", "scanner"}) {
    const Outcome r = sailshape(std::string(parent) + " --help");
    bool in_list = false;
    for (const std::string& line : lines(r.out)) {
      in_list = line == "Subcommands:" || (in_list && !line.empty());
      if (in_list) {
        EXPECT_LE(line.size(), 120u) << parent << ": " << line;
      }
    }
  }
}

// README's entry for a command: the bullet "- `sailshape NAME ..." up to the next bullet.
std::string readmeEntry(const std::string& readme, const std::string& name) {
  const size_t start = readme.find("\n- `sailshape " + name + " ");
  if (start == std::string::npos) return "";
  const size_t end = readme.find("\n- ", start + 1);
  return readme.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

TEST_F(Cli, ReadmeNamesTheOptionsAndTheDemosDefaultFolder) {
  const std::string readme = readText(fs::path(SAILSHAPE_ASSETS) / ".." / "README.md");
  ASSERT_FALSE(readme.empty());
  EXPECT_NE(readmeEntry(readme, "simulate").find("--points N"), std::string::npos) << readmeEntry(readme, "simulate");
  const std::string db = readmeEntry(readme, "db");
  EXPECT_NE(db.find("`db import DB FILE`"), std::string::npos) << db;
  EXPECT_NE(db.find("`--test NAME`"), std::string::npos) << db;
  EXPECT_NE(readmeEntry(readme, "analyze").find("--describe-params"), std::string::npos);

  // The folder `sailshape demo` writes to unless told: the one README (and scripts/demo) name.
  const Outcome help = sailshape("demo --help");
  const size_t at = help.out.find("--dir TEXT=");
  ASSERT_NE(at, std::string::npos) << help.out;
  std::istringstream rest(help.out.substr(at + 11));
  std::string folder;
  rest >> folder;
  EXPECT_EQ(folder, "demo-output");
  EXPECT_NE(readmeEntry(readme, "demo").find("(default `" + folder + "`"), std::string::npos)
      << readmeEntry(readme, "demo");
  EXPECT_NE(readText(fs::path(SAILSHAPE_ASSETS) / ".." / "scripts" / "demo").find("out=" + folder), std::string::npos);
}

TEST_F(Cli, AnalyzeHelpMentionsEveryOption) {
  const Outcome r = sailshape("analyze --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"INPUT", "--sections", "--at", "--plane", "--json", "--mesh", "--sail-cloud", "--params",
                         "--corners", "--scanner", "--sky", "--no-segment", "--print-params", "-q", "--quiet", "--design",
                         "--margin"});
}

TEST_F(Cli, SimulateHelpMentionsEveryOption) {
  const Outcome r = sailshape("simulate --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"--type", "--points", "--noise-mm", "--seed", "--scene", "--sections", "--out", "--truth"});
}

TEST_F(Cli, AMissingInputIsOneLineNamingTheFile) {
  const std::string missing = path("no_such_scan.ply");
  const Outcome r = sailshape("analyze " + missing);
  EXPECT_NE(r.exit_code, 0);
  const auto err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find(missing), std::string::npos) << err[0];
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(Cli, ACloudTooSmallToBeASailIsOneLineSayingHowManyItNeeds) {
  {
    std::ofstream out(path("three.xyz"));
    out << "0 0 0\n1 0 0\n0 1 0\n";
  }
  const Outcome r = sailshape("analyze " + path("three.xyz") + " -q");
  EXPECT_EQ(r.exit_code, 1);
  const auto err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  // The smoothing's neighbourhood (200 by default) is the largest any stage needs.
  EXPECT_NE(err[0].find("the cloud has 3 points: too few to be a sail's scan (the analysis needs at least 200"),
            std::string::npos)
      << err[0];
  EXPECT_EQ(err[0].find("["), std::string::npos) << "no internal function names: " << err[0];
}

TEST_F(Cli, AGarbagePlyIsOneClearLine) {
  // Not a PLY at all.
  const std::string junk = path("junk.ply");
  std::ofstream(junk, std::ios::binary) << "this is not a point cloud\n\x01\x02\x03\xff\n";
  Outcome r = sailshape("analyze " + junk);
  EXPECT_NE(r.exit_code, 0);
  auto err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find(junk), std::string::npos) << err[0];
  EXPECT_NE(err[0].find("PLY"), std::string::npos) << err[0];

  // A PLY header whose body breaks off into text.
  const std::string broken = path("broken.ply");
  std::ofstream(broken) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nend_header\n1 2 3\nfoo bar baz\n";
  r = sailshape("analyze " + broken);
  EXPECT_NE(r.exit_code, 0);
  err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find(broken), std::string::npos) << err[0];
}

// A cloud in millimetres, or scaled far beyond any scanner's reach, is one line naming
// what is wrong, before any analysis (which would report a 62-digit area).
TEST_F(Cli, ACloudNoScannerCouldMeasureIsOneLine) {
  const std::string mm = path("main_mm.xyz");
  std::ofstream(mm) << "0 0 1000\n-500 0 12400\n-3600 0 1300\n-1500 200 6000\n";
  Outcome r = sailshape("analyze " + mm);
  EXPECT_NE(r.exit_code, 0);
  auto err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find(mm + ": the cloud looks like millimetres"), std::string::npos) << err[0];
  const std::string huge = path("huge.xyz");
  std::ofstream(huge) << "0 0 1e30\n-5e29 0 1.24e31\n-3.6e30 0 1.3e30\n";
  r = sailshape("analyze " + huge);
  EXPECT_NE(r.exit_code, 0);
  err = lines(r.err);
  ASSERT_EQ(err.size(), 1u) << r.err;
  EXPECT_NE(err[0].find("reaches 1.24e+31 m from the origin"), std::string::npos) << err[0];
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(Cli, BadArgumentsAreOneLineWithExitCodeTwo) {
  Outcome r = sailshape("analyze --sections 0 " + path("x.ply"));  // range 1..100
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  r = sailshape("simulate --type catamaran --out " + path("x.ply"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_FALSE(fs::exists(path("x.ply")));
}

TEST_F(Cli, PrintParamsIsTheDefaultsAsJson) {
  const Outcome r = sailshape("analyze --print-params");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json doc;
  ASSERT_NO_THROW(doc = json::parse(r.out)) << r.out;
  ASSERT_TRUE(doc.contains("region_growing"));
  EXPECT_TRUE(doc["region_growing"].contains("k_neighbours"));
  EXPECT_EQ(doc, sailshape::paramsToJson(sailshape::AnalysisParams{}));
}

TEST_F(Cli, PrintParamsShowsAParameterFileAndTheOptionsApplied) {
  const std::string params = path("p.yaml");
  std::ofstream(params) << "region_growing:\n  max_normal_angle_deg: 7\n";
  const Outcome r = sailshape("analyze --params " + params + " --sections 5 --plane horizontal --print-params");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(r.out);
  EXPECT_EQ(doc["region_growing"]["max_normal_angle_deg"], 7.0);
  EXPECT_EQ(doc["sections"]["count"], 5);
  EXPECT_EQ(doc["sections"]["plane"], "horizontal");
  EXPECT_EQ(doc["outline"]["beam_exit_diameter_m"], 0.0) << "no beam unless the scanner is named";

  // --scanner sets its beam (SPEC §3: the LMS511's 13 mm exit and 4.7 mrad), any case.
  const Outcome named = sailshape("analyze --scanner LMS511 --print-params");
  ASSERT_EQ(named.exit_code, 0) << named.err;
  const json beam = json::parse(named.out)["outline"];
  EXPECT_EQ(beam["beam_exit_diameter_m"], 0.013);
  EXPECT_EQ(beam["beam_divergence_rad"], 0.0047);
  EXPECT_EQ(beam["edges_against_sky"], false) << "a tunnel's walls behind the edges unless --sky";
  EXPECT_EQ(sailshape("analyze --scanner lms200 --print-params").exit_code, 2);
  const Outcome sky = sailshape("analyze --scanner lms511 --sky --print-params");
  ASSERT_EQ(sky.exit_code, 0) << sky.err;
  EXPECT_EQ(json::parse(sky.out)["outline"]["edges_against_sky"], true);
}

// Flattens a parameter document into its dotted keys, as --describe-params names them.
void dottedKeys(const json& doc, const std::string& prefix, std::vector<std::pair<std::string, json>>& out) {
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it.value().is_object())
      dottedKeys(it.value(), key, out);
    else
      out.emplace_back(key, it.value());
  }
}

TEST_F(Cli, DescribeParamsGivesEveryParameterItsValueUnitAndMeaning) {
  const Outcome r = sailshape("analyze --sections 5 --scanner lms511 --describe-params");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::pair<std::string, json>> keys;
  dottedKeys(sailshape::paramsToJson(sailshape::AnalysisParams{}), "", keys);
  const std::vector<std::string> out = lines(r.out);
  ASSERT_EQ(out.size(), keys.size()) << r.out;
  for (size_t k = 0; k < keys.size(); ++k) {
    std::istringstream words(out[k]);
    std::string key, value, unit, first_word;
    words >> key >> value >> unit >> first_word;
    EXPECT_EQ(key, keys[k].first) << out[k];
    EXPECT_FALSE(first_word.empty()) << "no description: " << out[k];
    EXPECT_NE(unit, "?") << "no unit: " << out[k];
    EXPECT_EQ(out[k].find("(no description)"), std::string::npos) << out[k];
  }
  // The options given are applied, as --print-params shows them; units as SPEC and the names say.
  auto line = [&](const std::string& key) {
    for (const std::string& l : out)
      if (l.rfind(key + " ", 0) == 0) return l;
    return std::string();
  };
  std::istringstream count(line("sections.count"));
  std::string key, value;
  count >> key >> value;
  EXPECT_EQ(value, "5");
  std::istringstream beam(line("outline.beam_exit_diameter_m"));
  std::string unit;
  beam >> key >> value >> unit;
  EXPECT_EQ(value, "0.013");
  EXPECT_EQ(unit, "m");
  std::istringstream sigma(line("sensor_sigma_m"));
  sigma >> key >> value >> unit;
  EXPECT_EQ(value, "0.004");
  EXPECT_EQ(unit, "m");
  std::istringstream angle(line("region_growing.max_normal_angle_deg"));
  angle >> key >> value >> unit;
  EXPECT_EQ(unit, "deg");

  // The JSON form stays what --params files read; the two cannot be asked for together.
  EXPECT_EQ(sailshape("analyze --print-params --describe-params").exit_code, 2);
}

TEST_F(Cli, SimulatedMainIsMeasuredWithinHalfAPercentOfCamber) {
  const std::string cloud = path("main.ply"), truth_path = path("truth.json"), result_path = path("result.json");
  Outcome r = sailshape("simulate --type main --points 20000 --noise-mm 0 --out " + cloud + " --truth " + truth_path);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(cloud));
  const json truth = json::parse(readText(truth_path));
  ASSERT_EQ(truth["sections"].size(), 3u);

  r = sailshape("analyze " + cloud + " --json " + result_path + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << "--json replaces the table: " << r.out;
  const json result = json::parse(readText(result_path));

  // The sail: corners as [x, y, z] and the luff length.
  ASSERT_TRUE(result.contains("sail"));
  for (const char* corner : {"tack", "clew", "head"}) {
    ASSERT_TRUE(result["sail"].contains(corner)) << corner;
    ASSERT_EQ(result["sail"][corner].size(), 3u) << corner;
    // A corner is a boundary vertex of a ~3 cm point spacing (20000 points over ≈ 19 m²)
    // rounded by the edge smoothing: within 0.15 m of the design corner.
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 += std::pow(result["sail"][corner][i].get<double>() - truth[corner][i].get<double>(), 2);
    EXPECT_LT(std::sqrt(d2), 0.15) << corner;
  }
  ASSERT_TRUE(result["sail"].contains("luff_length_m"));
  EXPECT_GT(result["sail"]["luff_length_m"].get<double>(), 0.0);
  EXPECT_TRUE(result.contains("luff"));
  EXPECT_TRUE(result.contains("diagnostics"));
  EXPECT_EQ(result["diagnostics"]["points_in"], 20000);

  // Sections at 1/4, 1/2, 3/4 (SPEC §5), each with every parameter, its uncertainty and its curve.
  const json& sections = result["sections"];
  ASSERT_EQ(sections.size(), 3u);
  const double fractions[] = {0.25, 0.5, 0.75};
  for (size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE("section " + std::to_string(k));
    const json& s = sections[k];
    EXPECT_NEAR(s["fraction"].get<double>(), fractions[k], 1e-12);
    for (const char* key : {"chord_m", "camber_pct", "draft_pct", "twist_deg", "twist_rel_deg", "entry_deg",
                            "exit_deg"}) {
      ASSERT_TRUE(s.contains(key)) << key;
      ASSERT_TRUE(s["uncertainty"].contains(key)) << key;
    }
    for (const char* key : {"chord_m", "camber_pct", "draft_pct", "twist_deg", "twist_rel_deg"}) {
      EXPECT_TRUE(s[key].is_number()) << key << " = " << s[key];
      EXPECT_TRUE(s["uncertainty"][key].is_number()) << key << " = " << s["uncertainty"][key];
    }
    // An end angle needs 6 cut points near its end (10 % of the chord, widened to 20 % on a
    // sparse section); at this density (~3 cm spacing) a short upper chord may not have them.
    // Then it is null, with a warning.
    for (const char* key : {"entry_deg", "exit_deg"}) {
      if (s[key].is_number()) continue;
      EXPECT_TRUE(s[key].is_null()) << key << " = " << s[key];
      const std::string angle = std::string(key) == "entry_deg" ? "entry angle" : "exit angle";
      bool warned = false;
      for (const json& w : result["diagnostics"]["warnings"])
        warned = warned || w.get<std::string>().find("section " + fixed3(fractions[k]) + ": too few points for the " +
                                                     angle) != std::string::npos;
      EXPECT_TRUE(warned) << key << " is null without a warning";
      ASSERT_TRUE(s.contains("not_measured")) << "a null value is named as not measured";
      EXPECT_NE(s["not_measured"][key].get<std::string>().find("too few points for the " + angle), std::string::npos);
    }
    ASSERT_TRUE(s["curve"].is_array());
    EXPECT_GE(s["curve"].size(), 2u);
    for (const json& p : s["curve"]) ASSERT_EQ(p.size(), 3u);
    // Noise-free points, so only the surface's faceting and the section search stand
    // between the measurement and the design: 0.5 points of camber.
    const json& known = truth["sections"][k];
    EXPECT_NEAR(known["fraction"].get<double>(), fractions[k], 1e-12);
    EXPECT_NEAR(s["camber_pct"].get<double>(), known["camber_pct"].get<double>(), 0.5);
  }
  EXPECT_DOUBLE_EQ(sections[0]["twist_rel_deg"].get<double>(), 0.0);  // relative to the lowest section
}

// ---------------------------------------------------------------------------
// design new / design show / compare

TEST_F(Cli, DesignAndCompareHelpMentionEveryOption) {
  Outcome r = sailshape("design new --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"--type", "--luff", "--leech", "--foot", "--head-width", "--tack", "--rake-deg",
                         "--luff-round", "--luff-sag", "--leech-round", "--camber-pct", "--draft-pct", "--twist-deg",
                         "--entry", "--exit", "--starboard", "--rows", "--columns", "--sections", "--ascii", "--out"});
  r = sailshape("design show --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"FILE", "--unit", "--axes", "--sections", "--corners", "--json"});
  r = sailshape("compare --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"--design", "--flying", "--sections", "--json", "--distances", "--unit", "--axes",
                         "--params", "--no-segment", "--raw-distances", "--quiet"});
}

TEST_F(Cli, DesignNewThenShowReportsItsDimensions) {
  const std::string obj = path("A2.obj");
  Outcome r = sailshape("design new --type gennaker --luff 12.4 --leech 11 --foot 6.5 --camber-pct 18,24,16 --out " + obj);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(obj));
  r = sailshape("design show " + obj + " --json " + path("show.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(readText(path("show.json")));
  EXPECT_EQ(doc["unit"], "m");
  EXPECT_EQ(doc["axes"], "boat");
  EXPECT_NEAR(doc["sail"]["luff_straight_m"].get<double>(), 12.4, 0.02);
  EXPECT_NEAR(doc["sail"]["foot_straight_m"].get<double>(), 6.5, 0.02);
  // The generator's leech length is the planform's: twist and luff sag move the clew
  // and head apart in 3D (11.40 m here), so the leech is not checked against 11.
  ASSERT_EQ(doc["sections"].size(), 3u);
  EXPECT_NEAR(doc["sections"][1]["camber_pct"].get<double>(), 24.0, 0.1);  // the mid station

  r = sailshape("design new --type main --camber-pct 9,11 --out " + path("bad.obj"));
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("--camber-pct"), std::string::npos) << r.err;
  r = sailshape("design new --type main --luff -3 --out " + path("bad.obj"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(path("bad.obj")));
}

TEST_F(Cli, DesignShowOnTheSailcutJibMatchesItsDefinition) {
  const std::string dxf = std::string(SAILSHAPE_SHARED) + "/sailcut-examples/Star45-JIB.dxf";
  Outcome r = sailshape("design show " + dxf);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expectMentions(r.out, {"260 faces", "unit: millimetres (detected", "axes: sailcut", "luff", "leech", "foot"});
  r = sailshape("design show " + dxf + " --json " + path("jib.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(readText(path("jib.json")));
  EXPECT_EQ(doc["faces"], 260);
  EXPECT_NEAR(doc["sail"]["luff_straight_m"].get<double>(), 1.050, 0.005);
  EXPECT_NEAR(doc["sail"]["foot_straight_m"].get<double>(), 0.370, 0.005);
  EXPECT_NEAR(doc["sail"]["leech_straight_m"].get<double>(), 0.940, 0.005);

  const std::string broken = path("broken.dxf");
  std::ofstream(broken) << "0\nSECTION\n2\nENTITIES\n0\n3DFACE\n10\n1.5\n20\nabc\n";
  r = sailshape("design show " + broken);
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(lines(r.err).size(), 1u) << r.err;
  expectMentions(r.err, {broken, "line 10", "non-numeric"});
}

TEST_F(Cli, CompareADeeperFlyingMeshWithItsDesign) {
  ASSERT_EQ(sailshape("design new --type main --out " + path("design.ply")).exit_code, 0);
  ASSERT_EQ(sailshape("design new --type main --camber-pct 11,13,10 --out " + path("flying.stl")).exit_code, 0);
  Outcome r = sailshape("compare --design " + path("design.ply") + " --flying " + path("flying.stl") +
                        " -q --json " + path("cmp.json") + " --distances " + path("d.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(readText(path("cmp.json")));
  EXPECT_EQ(doc["flying"]["kind"], "mesh");
  EXPECT_GT(doc["distance"]["mean_m"].get<double>(), 0.0);  // deeper = to leeward
  EXPECT_GT(doc["distance"]["leeward"][1].get<double>(), 0.7);
  ASSERT_EQ(doc["sections"].size(), 3u);
  for (const auto& s : doc["sections"]) EXPECT_NEAR(s["delta"]["camber_pct"].get<double>(), 2.0, 0.2) << s.dump();
  EXPECT_TRUE(fs::exists(path("d.csv")));

  r = sailshape("compare --design " + path("design.ply") + " --flying " + path("nothing.xyz"));
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("nothing.xyz"), std::string::npos) << r.err;
}

TEST_F(Cli, CompareNamesASectionTheFlyingScanCouldNotMeasure) {
  ASSERT_EQ(sailshape("design new --type main --out " + path("design.ply")).exit_code, 0);
  ASSERT_EQ(sailshape("simulate --type main --points 40000 --out " + path("scan.xyz") + " --truth " + path("t.json")).exit_code, 0);
  // A hole half the mid section's chord wide, centred on it: too wide to bridge.
  ASSERT_EQ(sailshape("analyze " + path("scan.xyz") + " -q --json " + path("a.json")).exit_code, 0);
  const json mid = json::parse(readText(path("a.json")))["sections"][1];
  Eigen::Vector3d luff, leech;
  for (int i = 0; i < 3; ++i) {
    luff[i] = mid["luff_point"][i].get<double>();
    leech[i] = mid["leech_point"][i].get<double>();
  }
  const Eigen::Vector3d centre = 0.5 * (luff + leech);
  const double radius = 0.25 * (leech - luff).norm();
  {
    std::ifstream in(path("scan.xyz"));
    std::ofstream out(path("holed.xyz"));
    for (std::string line; std::getline(in, line);) {
      Eigen::Vector3d p;
      if (line.empty() || line[0] == '#' || !(std::istringstream(line) >> p.x() >> p.y() >> p.z()) ||
          (p - centre).norm() > radius)
        out << line << "\n";
    }
  }
  Outcome r = sailshape("compare --design " + path("design.ply") + " --flying " + path("holed.xyz") + " -q --json " +
                        path("cmp.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(readText(path("cmp.json")));
  ASSERT_EQ(doc["sections"].size(), 2u);
  EXPECT_DOUBLE_EQ(doc["sections"][0]["fraction"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(doc["sections"][1]["fraction"].get<double>(), 0.75);
  ASSERT_EQ(doc["unmeasured_sections"].size(), 1u);
  EXPECT_DOUBLE_EQ(doc["unmeasured_sections"][0]["fraction"].get<double>(), 0.5);
  EXPECT_EQ(doc["unmeasured_sections"][0]["side"], "flying");
  EXPECT_NE(doc["unmeasured_sections"][0]["reason"].get<std::string>().find("crosses a hole"), std::string::npos);
  r = sailshape("compare --design " + path("design.ply") + " --flying " + path("holed.xyz") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("50% not measured on the flying: the section plane at fraction 0.500 crosses a hole"),
            std::string::npos)
      << r.out;
}

TEST_F(Cli, CompareGivesTheDistancesOfAPatchAndListsWhatItCouldNotMeasure) {
  ASSERT_EQ(sailshape("design new --type main --out " + path("design.ply")).exit_code, 0);
  ASSERT_EQ(sailshape("simulate --type main --points 40000 --out " + path("scan.xyz") + " --truth " + path("t.json")).exit_code, 0);
  // A patch of the mid-leech, 3 m high and about 1.7 m wide, moved 30 mm to port (the sail's leeward side):
  // no corner, no whole section in it.
  constexpr double kShiftM = 0.030;
  {
    std::ifstream in(path("scan.xyz"));
    std::ofstream out(path("patch.xyz"));
    for (std::string line; std::getline(in, line);) {
      Eigen::Vector3d p;
      if (line.empty() || line[0] == '#' || !(std::istringstream(line) >> p.x() >> p.y() >> p.z())) continue;
      if (p.z() > 4 && p.z() < 7 && p.x() > -2.5 && p.x() < -0.8)
        out << p.x() << " " << p.y() + kShiftM << " " << p.z() << "\n";
    }
  }
  Outcome r = sailshape("compare --design " + path("design.ply") + " --flying " + path("patch.xyz") + " -q --json " +
                        path("cmp.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(readText(path("cmp.json")));
  EXPECT_GT(doc["distance"]["count"].get<int>(), 5000);
  // Moved by s along +Y, a point lies s·n_y from the surface, n the design's normal there; over this patch
  // the main's normal is within 25° of +Y (n_y 0.9 to 1). The smoothed scan sits on the design within a mm.
  const double mean = doc["distance"]["mean_m"].get<double>();
  EXPECT_GT(mean, 0.9 * kShiftM - 0.001);
  EXPECT_LT(mean, kShiftM + 0.001);
  EXPECT_LT(doc["distance"]["p95_m"].get<double>() - doc["distance"]["p5_m"].get<double>(), 0.1 * kShiftM + 0.004);
  // The outline and every section are named as not measured on the flying side, and why.
  EXPECT_NE(doc["flying"]["outline"].get<std::string>().find("not measured: "), std::string::npos);
  EXPECT_EQ(doc["flying"]["outline"].get<std::string>().find("[extract"), std::string::npos) << "no internal names";
  EXPECT_EQ(doc["sections"].size(), 0u);
  ASSERT_EQ(doc["unmeasured_sections"].size(), 3u);
  for (const auto& u : doc["unmeasured_sections"]) {
    EXPECT_EQ(u["side"], "flying");
    EXPECT_EQ(u["reason"], "no outline on the flying shape");
  }
  r = sailshape("compare --design " + path("design.ply") + " --flying " + path("patch.xyz") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Outline and sections not measured on the flying shape: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("50% not measured on the flying: no outline on the flying shape"), std::string::npos) << r.out;
}

// The tree as the README draws it: every analysis sub-library is a folder with a
// README and a CMake target, named in the README's layout table, and no source file
// in analysis/ is longer than a reader can hold (about 900 lines).
TEST(Layout, EveryAnalysisFolderHasAReadmeARowInTheLayoutTableAndNoFileOver900Lines) {
  const fs::path root = fs::path(SAILSHAPE_ASSETS) / "..";
  const std::string readme = readText(root / "README.md");
  ASSERT_FALSE(readme.empty());
  size_t folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(root / "analysis")) {
    if (!e.is_directory()) continue;
    ++folders;
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(fs::exists(e.path() / "README.md")) << name;
    EXPECT_TRUE(fs::exists(e.path() / "CMakeLists.txt")) << name;
    EXPECT_NE(readme.find("| `analysis/" + name + "/` |"), std::string::npos) << name << " is not in the layout table";
    for (const fs::directory_entry& f : fs::directory_iterator(e.path())) {
      const std::string ext = f.path().extension().string();
      if (ext != ".cpp" && ext != ".hpp") continue;
      std::ifstream in(f.path());
      size_t lines = 0;
      for (std::string line; std::getline(in, line);) ++lines;
      EXPECT_LE(lines, 900u) << f.path();
    }
  }
  EXPECT_GE(folders, 10u);
  EXPECT_TRUE(fs::exists(root / "tests" / "support" / "README.md"));
}

}  // namespace
