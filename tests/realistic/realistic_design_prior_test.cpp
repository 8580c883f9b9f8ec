// `analyze --design` on realistic one-unit scans (issue 37 item 3): a main flying 3 % deeper and
// 2° + 10°·f more twisted than its design, swept by one unit from the leeward deck, whose head
// the scan often misses (out of range, grazing). The scan alone then refuses its sections; with
// the design fitted onto its samples every value it reports is judged against the flying sail's
// truth (tests/support/realistic_judge.hpp): none may be confidently wrong (|error| > 3σ +
// target). SAILSHAPE_REALISTIC_SEED replays a run, SAILSHAPE_REALISTIC_COUNT draws more.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "analysis/core/errors.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/io/mesh_io.hpp"
#include "analysis/pipeline/design_prior.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "tests/cli/run_sailshape.hpp"
#include "tests/support/fit_case.hpp"
#include "tests/support/realistic_judge.hpp"

namespace sailshape::realistic {
namespace {

TEST(RealisticDesignPrior, ScansThatMissedTheHeadGetHonestSectionsFromTheFittedDesign) {
  uint64_t base = std::random_device{}() | (static_cast<uint64_t>(std::random_device{}()) << 32);
  if (const char* s = std::getenv("SAILSHAPE_REALISTIC_SEED")) base = std::strtoull(s, nullptr, 10);
  size_t count = 4;
  if (const char* s = std::getenv("SAILSHAPE_REALISTIC_COUNT")) count = std::strtoul(s, nullptr, 10);
  std::printf("SAILSHAPE_REALISTIC_SEED=%llu (replays this run)\n", static_cast<unsigned long long>(base));
  std::mt19937_64 rng(base);
  size_t fitted = 0, inferred_sections = 0;
  for (size_t i = 0; i < count; ++i) {
    const SailKind kind = i % 2 == 0 ? SailKind::SquareTopMain : SailKind::PinHeadMain;
    Config config = drawConfig(rng() >> 1, kind, UnitPlace::DeckLeeward);
    const SailDesign design = config.design;
    config.design = deeperAndMoreTwisted(design);
    const Scan scan = sweepScene(config, buildScene(config), 2);
    const int rows = std::max(80, static_cast<int>(std::ceil(design.luff_m / 0.125)));
    const int columns = std::max(40, static_cast<int>(std::ceil(design.foot_m / 0.09)));
    const Mesh design_mesh = generateSailMesh(design, rows, columns);
    const Truth truth = truthOf(config.design);
    VariantResult r;
    r.variant = "own-scan+design";
    try {
      const AnalysisParams params;
      SectionParams exact = params.sections;
      exact.sensor_sigma_m = 0;  // a design has no measurement noise (as `analyze --design` reads it)
      const MeshSections design_sections = analyzeMeshSections(design_mesh, {}, exact);
      const SailAnalysis a = analyzeWithDesign(scan.cloud, designRegion(design_mesh, plausibleTrimDeviationM(design_mesh)),
                                               design_mesh, design_sections, params);
      judgeAnalysis(&a, "", truth, config.design, Targets{}, r);
      if (a.design_fit) {
        ++fitted;
        for (const Section& s : a.sections.sections) {
          inferred_sections += s.inferred_pct > 0 ? 1 : 0;
          std::printf("  section %.2f: %.0f %% inferred\n", s.fraction, s.inferred_pct);
        }
      }
      std::printf("%s: %s\n", config.summary().c_str(),
                  a.design_fit ? ("design fitted in: " + a.inferred_because).c_str() : "the scan alone");
    } catch (const AnalysisError& e) {
      std::printf("%s: refused: %s\n", config.summary().c_str(), e.what());
      judgeAnalysis(nullptr, e.what(), truth, config.design, Targets{}, r);
    }
    for (const JudgedValue& v : r.values) {
      std::printf("  %-16s %-8s error %.4g σ %.4g%s%s\n", v.name.c_str(), verdictName(v.verdict).c_str(), v.error,
                  v.sigma, v.reason.empty() ? "" : ": ", v.reason.c_str());
      if (v.verdict == Verdict::Wrong)
        ADD_FAILURE() << "confidently wrong: " << config.summary() << ": " << v.name << " off by " << v.error
                      << ", σ " << v.sigma;
    }
    std::fflush(stdout);
  }
  std::printf("design fitted in on %zu of %zu scans, %zu sections inferred in part\n", fitted, count, inferred_sections);
}

}  // namespace
}  // namespace sailshape::realistic

namespace sailshape::realistic {
namespace {

namespace fs = std::filesystem;

// The same as a user runs it: the scan and the design as files, `analyze --design --fitted --json`.
TEST(RealisticDesignPrior, AnalyzeCommandReportsWhatWasInferredAndWritesTheFittedDesign) {
  const uint64_t seed = freshSeed();
  Config config = drawConfig(seed, SailKind::SquareTopMain, UnitPlace::DeckLeeward);
  std::printf("%s\n", config.summary().c_str());
  const SailDesign design = config.design;
  config.design = deeperAndMoreTwisted(design);
  const Scan scan = sweepScene(config, buildScene(config), 2);
  const Mesh design_mesh = generateSailMesh(design, std::max(80, static_cast<int>(std::ceil(design.luff_m / 0.125))),
                                            std::max(40, static_cast<int>(std::ceil(design.foot_m / 0.09))));
  const fs::path dir = fs::temp_directory_path() / ("sailshape-design-prior-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  writeCloud((dir / "scan.ply").string(), scan.cloud);
  writeMesh((dir / "design.obj").string(), design_mesh);
  const testing::Outcome r = testing::runSailshape(
      dir, "analyze " + (dir / "scan.ply").string() + " --design " + (dir / "design.obj").string() + " --fitted " +
               (dir / "fitted.ply").string() + " --json " + (dir / "a.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "a.json");
  const nlohmann::json doc = nlohmann::json::parse(in);
  const nlohmann::json& fit = doc["design"]["fit"];
  if (fit.is_null()) {
    // The scan alone measured every section: nothing inferred, no fitted design to write.
    std::printf("the scan reached every corner: the design was not fitted in\n");
    EXPECT_FALSE(fs::exists(dir / "fitted.ply"));
    for (const auto& s : doc["sections"]) EXPECT_EQ(s["inferred_pct"].get<double>(), 0.0);
  } else {
    std::printf("design fitted in: %s\n", fit["because"].get<std::string>().c_str());
    EXPECT_FALSE(fit["because"].get<std::string>().empty());
    EXPECT_GT(fit["coverage"].get<double>(), 0.0);
    EXPECT_LT(fit["coverage"].get<double>(), 1.0);
    // The fitted design: its vertices in order, its triangles unchanged.
    const Mesh fitted = readMesh((dir / "fitted.ply").string());
    EXPECT_EQ(fitted.vertices.size(), design_mesh.vertices.size());
    EXPECT_EQ(fitted.triangles, design_mesh.triangles);
    // The top section lies beyond the samples of a one-unit deck scan, in part at least.
    ASSERT_FALSE(doc["sections"].empty());
    EXPECT_GT(doc["sections"].back()["inferred_pct"].get<double>(), 0.0);
    // And the head, scanned or inferred, within 3σ + the suite's 5 cm of the flying sail's.
    const Truth truth = truthOf(config.design);
    const auto& h = doc["sail"]["head"];
    const Vec3 head(h[0].get<double>(), h[1].get<double>(), h[2].get<double>());
    EXPECT_LE((head - truth.head).norm(), 3 * doc["sail"]["uncertainty"]["head_m"].get<double>() + 0.05);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sailshape::realistic

namespace sailshape::realistic {
namespace {

// A plain cloud (no scanner position) of a sail scanned up to 88 % of its height (issue 37's
// known answer, tests/support/fit_case.hpp): alone the outline puts a head where the samples
// stop; against the design its luff is too short, the head was not reached, and the fitted
// design stands in, every value honest.
TEST(RealisticDesignPrior, APlainCloudShortOfTheHeadIsToldByItsDesign) {
  FitCaseOptions o;
  o.seed = freshSeed();
  std::printf("seed %llu\n", static_cast<unsigned long long>(o.seed));
  o.hole_h_from = o.hole_h_to = 0.5;  // no interior hole: the top alone is missing
  const FitCase c = makeFitCase(o);
  const Cloud plain = plainXyz(c.scan);  // as another program exports it: points only
  AnalysisParams params;
  params.sections.fractions = {0.25, 0.5, 0.75, 0.94};
  SectionParams exact = params.sections;
  exact.sensor_sigma_m = 0;
  const MeshSections design_sections = analyzeMeshSections(c.design_mesh, {}, exact);
  const SailAnalysis a = analyzeWithDesign(plain, designRegion(c.design_mesh, plausibleTrimDeviationM(c.design_mesh)),
                                           c.design_mesh, design_sections, params);
  ASSERT_TRUE(a.design_fit.has_value()) << "the head at 88 % of the luff was reported as the sail's";
  std::printf("design fitted in: %s\n", a.inferred_because.c_str());
  EXPECT_NE(a.inferred_because.find("did not reach the head"), std::string::npos) << a.inferred_because;
  EXPECT_FALSE(a.outline.coverage.head);
  EXPECT_TRUE(a.outline.coverage.tack && a.outline.coverage.clew);
  VariantResult r;
  judgeAnalysis(&a, "", truthOf(c.flying), c.flying, Targets{}, r);
  size_t within = 0;
  for (const JudgedValue& v : r.values) {
    std::printf("  %-16s %-8s error %.4g σ %.4g\n", v.name.c_str(), verdictName(v.verdict).c_str(), v.error, v.sigma);
    EXPECT_NE(v.verdict, Verdict::Wrong) << v.name << " off by " << v.error << ", σ " << v.sigma;
    within += v.verdict == Verdict::Within ? 1 : 0;
  }
  // Below the top the sections run through samples and are measured on the scan's surface; the
  // one at 94 %, above the samples, is cut on the fitted design.
  ASSERT_EQ(a.sections.sections.size(), 4u);
  for (const Section& s : a.sections.sections) std::printf("  section %.2f: %.0f %% inferred\n", s.fraction, s.inferred_pct);
  EXPECT_EQ(a.sections.sections.front().inferred_pct, 0.0);
  EXPECT_GT(a.sections.sections.back().inferred_pct, 50.0);
  // Sections from the scan and from the fitted design, their twist_rel from the one lowest.
  for (const Section& s : a.sections.sections)
    EXPECT_DOUBLE_EQ(s.value.twist_rel_deg, s.value.twist_deg - a.sections.sections.front().value.twist_deg);
}

}  // namespace
}  // namespace sailshape::realistic
