// The built sailshape-viewer run as a user would, under a private X server
// (xvfb-run), judged by what its screenshot shows.
#include <gtest/gtest.h>
#include <stb_image.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>

#include "database/scan_record.hpp"
#include "tests/database/pg_cluster.hpp"
#include "viewer/catalog_tree.hpp"
#include "viewer_fixture.hpp"
#include "viewer_run.hpp"

namespace sailshape::viewer {
namespace {

using namespace run_test;

class ViewerApp : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    test::makeSailDatabase(dir_->file("sails.sqlite"), 2);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static test::TempDir* dir_;
};
test::TempDir* ViewerApp::dir_ = nullptr;

// One run covers the shell and the Report button (each run loads and analyses the scan again).
TEST_F(ViewerApp, ShowsDesignAndFlyingDrawsThePanelsAndWritesTheReport) {
  const std::string png = dir_->file("shot.png");
  const std::string pdf = dir_->file("report.pdf");
  const ViewerRun r = runViewer(*dir_, quote(dir_->file("sails.sqlite")) + " --report " + quote(pdf) +
                                           " --pick 0.55,0.55 --screenshot " + quote(png) + " --frames 4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const Image img = load(png);
  ASSERT_TRUE(img.rgb) << "no PNG at " << png;
  ASSERT_EQ(img.width, kWidth);
  ASSERT_EQ(img.height, kHeight);
  // The flying surface fills a good part of the view, the design grid runs over it.
  EXPECT_GT(count(img, kView, kRed) / area(kView), 0.03);
  EXPECT_GT(count(img, kView, kBlue) / area(kView), 0.002);
  // Plots: the design (blue) and flying (red) curves of camber, draft and twist.
  EXPECT_GT(count(img, kPlots, kRed), 150u);
  EXPECT_GT(count(img, kPlots, kBlue), 150u);
  // Browser tree and section table carry text.
  EXPECT_GT(count(img, kBrowser, kText), 300u);
  EXPECT_GT(count(img, kAnalysis, kText), 1000u);
  // No scalar bar without deviation colours.
  EXPECT_LT(count(img, kScalarBar, kRed), 20u);
  // A click in the middle of the view picks the flying surface: a point of the 10 m sail (tack at z = 1 m),
  // to leeward of the design by what +2 % camber and +3° twist give (p5 > −3σ; the leech moves ≤ 0.25 m).
  const auto at = r.out.find("picked flying surface at ");
  ASSERT_NE(at, std::string::npos) << r.out;
  double x = 0, y = 0, z = 0, deviation_mm = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str() + at, "picked flying surface at %lf %lf %lf m, deviation %lf mm", &x, &y, &z,
                        &deviation_mm),
            4)
      << r.out;
  EXPECT_GT(z, 1.0);
  EXPECT_LT(z, 11.0);
  EXPECT_GT(deviation_mm, -3 * 1000 * test::kSensorSigmaM);
  EXPECT_LT(deviation_mm, 250.0);
  // The Report button's PDF, written whole.
  const std::string bytes = slurp(pdf);
  ASSERT_GT(bytes.size(), 10'000u) << "no report at " << pdf;
  EXPECT_EQ(bytes.substr(0, 5), "%PDF-");
  EXPECT_NE(bytes.find("%%EOF", bytes.size() - 32), std::string::npos) << "the PDF is complete";
}

// Deviation colours, and a window shrunk until the 3D view has no pixels, minimised and restored.
TEST_F(ViewerApp, DeviationColoursAndSurvivingResizeAndMinimise) {
  const std::string png = dir_->file("deviation.png");
  const ViewerRun r = runViewer(*dir_, quote(dir_->file("sails.sqlite")) + " --deviation --exercise-window --screenshot " +
                                           quote(png) + " --frames 20");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load(png);
  ASSERT_TRUE(img.rgb);
  ASSERT_EQ(img.width, kWidth) << "the window is back at its size after the exercise";
  ASSERT_EQ(img.height, kHeight);
  // Cool-to-warm: the bar spans blue (to windward) to red (to leeward) ...
  const Pixel bluish = [](int r, int, int b) { return b > r + 60; };
  const Pixel reddish = [](int r, int, int b) { return r > b + 60; };
  EXPECT_GT(count(img, kScalarBar, bluish), 200u);
  EXPECT_GT(count(img, kScalarBar, reddish), 200u);
  // ... and the flying shape, almost all to leeward of the design, is drawn warm.
  EXPECT_GT(count(img, kView, reddish) / area(kView), 0.03);
}

// Live mode as scripted by --live: an emulated deck unit sweeps until two sweeps are analysed, every sweep is
// stored, and the view, from the unit (--camera unit), shows the last one's sail cluster (--show) against the design.
void expectLiveModeShowsEachAnalysedSweepAndStoresIt(const test::TempDir& dir, const std::string& db) {
  { Database created = openSailDatabase(db); }
  const std::string png = dir.file("live.png");
  const ViewerRun r = runViewer(dir, quote(db) + " --live 2 --camera unit --show design,cluster,sections,design-sections --screenshot " +
                                           quote(png) + " --frames 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int swept = 0, analysed = 0, failed = 0;
  const auto at = r.out.find("live: ");
  ASSERT_NE(at, std::string::npos) << r.out;
  ASSERT_EQ(std::sscanf(r.out.c_str() + at, "live: %d swept, %d analysed, %d failed", &swept, &analysed, &failed), 3) << r.out;
  EXPECT_GE(analysed, 2) << "a sweep already taken when live mode stops is analysed too";
  EXPECT_EQ(swept, analysed + failed);
  // A failed analysis is reported (on stderr as in the panel), never as a crash.
  if (failed == 0) {
    EXPECT_EQ(r.err, "");
  }

  const Image img = load(png);
  ASSERT_TRUE(img.rgb);
  // The sail cluster's green points over the design's blue grid; no flying surface was asked for
  // (the red left is the legend's swatch).
  const Pixel green = [](int r, int g, int b) { return g > 150 && g > r + 80 && g > b + 50; };
  // The unit's camera looks along its sweep's centre, so the sail it scanned is in view (a camera turned
  // away would show none of it): about 2,700 cluster points, 3 px each.
  EXPECT_GT(count(img, kView, green) / area(kView), 0.01);
  EXPECT_GT(count(img, kView, kBlue) / area(kView), 0.002);
  EXPECT_LT(count(img, kView, kRed) / area(kView), 0.002);
  // The live sweep's sections against the design's in the plots; the Scanners tab with live mode's status.
  EXPECT_GT(count(img, kPlots, kRed), 150u);
  EXPECT_GT(count(img, kPlots, kBlue), 150u);
  EXPECT_GT(count(img, kAnalysis, kText), 1000u);
  EXPECT_GT(count(img, kBrowser, kText), 200u) << "the stored sweeps are listed";
  // The unit's view puts the sail anywhere in the picture: the mouse hint is in the title bar, not over it.
  const Pixel hint_grey = [](int r, int g, int b) {
    return r > 120 && r < 200 && g > 120 && g < 200 && b > 120 && b < 210 && std::abs(r - b) < 25;
  };
  EXPECT_EQ(count(img, Rect{700, 590, 1150, 626}, hint_grey), 0u);
  EXPECT_GT(count(img, Rect{380, 40, 760, 60}, kText), 200u);

  Database stored = openSailDatabase(db);
  const CatalogTree tree = loadCatalogTree(stored);
  EXPECT_EQ(tree.scan_count, static_cast<size_t>(swept)) << "every sweep is stored";
  size_t with_sections = 0;
  for (int64_t id : tree.scanIds()) with_sections += loadScanRecord(stored, id).sections.sections.size() == 2;
  EXPECT_EQ(with_sections, static_cast<size_t>(analysed)) << "each analysed sweep with its two sections";
}

TEST_F(ViewerApp, LiveModeShowsEachAnalysedSweepAndStoresIt) {
  expectLiveModeShowsEachAnalysedSweepAndStoresIt(*dir_, dir_->file("live.sqlite"));
}

// The same into the loft's shared store (issue 38): the viewer opens a PostgreSQL URL and
// live mode stores every sweep there.
TEST_F(ViewerApp, LiveModeStoresIntoAPostgreSQLStore) {
  std::string url;
  try {
    url = sailshape::test::PgCluster::shared().createDatabase();
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
  expectLiveModeShowsEachAnalysedSweepAndStoresIt(*dir_, url);
}

TEST_F(ViewerApp, OpensAnEmptyDatabase) {
  const std::string db = dir_->file("empty.sqlite");
  { Database created = openSailDatabase(db); }
  const std::string png = dir_->file("empty.png");
  const ViewerRun r = runViewer(*dir_, quote(db) + " --screenshot " + quote(png) + " --frames 3");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const Image img = load(png);
  ASSERT_TRUE(img.rgb);
  EXPECT_LT(count(img, kView, kRed), 50u);
  EXPECT_LT(count(img, kView, kBlue), 50u);
  EXPECT_GT(count(img, kView, kText), 50u) << "the view says the database has no scans";
  EXPECT_GT(count(img, kBrowser, kText), 100u);
}

TEST_F(ViewerApp, AMissingFileIsReportedAndNotCreated) {
  const std::string missing = dir_->file("no-such.sqlite");
  const std::string png = dir_->file("missing.png");
  const ViewerRun r = runViewer(*dir_, quote(missing) + " --screenshot " + quote(png) + " --frames 3");
  // A script learns it from the exit status and one line; the screenshot shows what a person would see.
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("database file not found: " + missing), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(missing));
  const Image img = load(png);
  ASSERT_TRUE(img.rgb);
  EXPECT_GT(count(img, kView, kErrorText), 30u) << "the message is in the 3D view";
  EXPECT_GT(count(img, kBrowser, kErrorText), 30u) << "and in the browser";
}

TEST_F(ViewerApp, RefusesBadOptions) {
  const ViewerRun no_frames = runViewer(*dir_, "--screenshot " + quote(dir_->file("x.png")));
  EXPECT_NE(no_frames.exit_code, 0);
  EXPECT_NE(no_frames.err.find("--frames"), std::string::npos) << no_frames.err;
  EXPECT_FALSE(std::filesystem::exists(dir_->file("x.png")));
  const ViewerRun bad_pick = runViewer(*dir_, "--pick 2,0.5 --screenshot " + quote(dir_->file("x.png")) + " --frames 2");
  EXPECT_NE(bad_pick.exit_code, 0) << "a pick outside the view";
  const ViewerRun bad_layer = runViewer(*dir_, "--show design,hull --screenshot " + quote(dir_->file("x.png")) + " --frames 2");
  EXPECT_NE(bad_layer.exit_code, 0);
  EXPECT_NE(bad_layer.err.find("unknown layer 'hull'"), std::string::npos) << bad_layer.err;
  const ViewerRun bad_camera = runViewer(*dir_, "--camera masthead --screenshot " + quote(dir_->file("x.png")) + " --frames 2");
  EXPECT_NE(bad_camera.exit_code, 0);
  EXPECT_NE(bad_camera.err.find("--camera"), std::string::npos) << bad_camera.err;
  const ViewerRun unit_without_units =
      runViewer(*dir_, quote(dir_->file("sails.sqlite")) + " --camera unit --screenshot " + quote(dir_->file("x.png")) + " --frames 2");
  EXPECT_NE(unit_without_units.exit_code, 0);
  EXPECT_NE(unit_without_units.err.find("no scanner unit"), std::string::npos) << unit_without_units.err;
  const ViewerRun live_alone = runViewer(*dir_, "--live 2");
  EXPECT_NE(live_alone.exit_code, 0);
  EXPECT_NE(live_alone.err.find("--screenshot"), std::string::npos) << live_alone.err;
  const ViewerRun state_alone = runViewer(*dir_, quote(dir_->file("sails.sqlite")) + " --state " + quote(dir_->file("x.json")));
  EXPECT_NE(state_alone.exit_code, 0);
  EXPECT_NE(state_alone.err.find("--screenshot"), std::string::npos) << state_alone.err;
  EXPECT_FALSE(std::filesystem::exists(dir_->file("x.json")));
  const ViewerRun report_alone = runViewer(*dir_, "--report " + quote(dir_->file("x.pdf")));
  EXPECT_NE(report_alone.exit_code, 0);
  EXPECT_NE(report_alone.err.find("--screenshot"), std::string::npos) << report_alone.err;
}

}  // namespace
}  // namespace sailshape::viewer
