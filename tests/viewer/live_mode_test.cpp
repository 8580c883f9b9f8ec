// Live mode's controller driving an emulated deck unit through the real protocols
// (turntable on a pty, SICK CoLa on TCP): sweep after sweep analysed on its own
// thread, results for the section table, every sweep stored, stop, and an analysis
// that fails reported without ending the loop.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "acquisition/scene.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/io/cloud_io.hpp"
#include "analysis/segmentation/spars.hpp"
#include "database/scan_record.hpp"
#include "viewer/catalog_tree.hpp"
#include "viewer/live_mode.hpp"
#include "viewer/section_table.hpp"
#include "viewer_fixture.hpp"

namespace sailshape::viewer {
namespace {

// The built-in deck scene flies the example mainsail exactly as designed.
Mesh deckMain() { return generateSailMesh(exampleDesign(SailType::Main)); }

// deckUnit(): 30 °/s at 50 Hz, 0.6° between scan lines, about 0.1 m at the head 12 m away. Faster
// sweeps leave the upper sail too sparse for its sections (camber 3 % low at 40 °/s).
UnitConfig quickDeckUnit() { return deckUnit(); }

// Collects live results until `done` holds or live mode ends. The limit only keeps a
// broken emulator from hanging the suite (a sweep takes a few seconds).
std::vector<LiveSweep> collect(LiveMode& live, const std::function<bool(const std::vector<LiveSweep>&)>& done,
                               std::vector<LiveSweep> got = {}) {
  const auto t0 = std::chrono::steady_clock::now();
  while (!done(got) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(240)) {
    for (LiveSweep& s : live.take()) got.push_back(std::move(s));
    if (!live.running()) {
      for (LiveSweep& s : live.take()) got.push_back(std::move(s));
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return got;
}

size_t analysed(const std::vector<LiveSweep>& v) {
  size_t n = 0;
  for (const auto& s : v) n += s.scene.has_value();
  return n;
}

TEST(LiveMode, SweepsAreAnalysedOneAfterAnotherAFailureIsReportedAndStopEndsIt) {
  test::TempDir dir;
  const std::string db_path = dir.file("live.sqlite");
  { Database created = openSailDatabase(db_path); }
  ScannerSession session;
  session.addEmulatedUnit(builtInDeckScene(), "deck", quickDeckUnit());

  const Mesh design = deckMain();
  SceneOptions good;
  good.roi = sailRoi(design, 0.3);
  good.analysis = designedSailParams(design, 2);
  // Checked against a sail half the size, every outline is "off the design": the analysis must fail.
  SceneOptions failing = good;
  failing.analysis = designedSailParams(generateSailMesh(scaleDesign(exampleDesign(SailType::Main), 0.5)), 2);

  LiveParams params;
  params.scene = failing;
  params.design = design;
  params.save_to = db_path;
  params.form.campaign = "Deck trials";
  params.form.sail = "main-A";
  params.form.test = "live";
  params.form.step = 1;
  LiveMode live;
  live.start(session, params);
  EXPECT_THROW(live.start(session, params), std::logic_error) << "one live run at a time";

  std::vector<LiveSweep> got = collect(live, [](const auto& v) { return !v.empty(); });
  ASSERT_FALSE(got.empty()) << live.status().error;
  EXPECT_FALSE(got[0].scene.has_value());
  // Usually the outline check ("... off the design"); a sweep whose corners were not found fails earlier,
  // in the same stage. Either way the message names the function that failed.
  EXPECT_EQ(got[0].error.rfind("[extractOutline]", 0), 0u) << got[0].error;
  EXPECT_TRUE(live.running()) << "a failed analysis does not end live mode";

  live.setSceneOptions(good);
  got = collect(live, [](const auto& v) { return analysed(v) >= 2; }, std::move(got));
  live.stop();
  for (LiveSweep& s : live.take()) got.push_back(std::move(s));  // a sweep taken before the stop is still analysed
  EXPECT_FALSE(live.running());
  const LiveStatus st = live.status();
  EXPECT_EQ(st.error, "");
  EXPECT_EQ(st.stage, "stopped");
  ASSERT_GE(analysed(got), 2u) << "swept " << st.swept << ", failed " << st.failed;
  EXPECT_EQ(static_cast<size_t>(st.analysed + st.failed), got.size());
  EXPECT_EQ(st.swept, st.analysed + st.failed + st.skipped);

  int previous = 0;
  size_t stored = 0;
  for (const LiveSweep& s : got) {
    EXPECT_GT(s.index, previous) << "results arrive in sweep order";
    previous = s.index;
    EXPECT_GT(s.points, 1000u);
    EXPECT_EQ(s.store_error, "");
    EXPECT_GT(s.scan_id, 0) << "every sweep is stored";
    stored += s.scan_id > 0;
    if (!s.scene) continue;
    // The section table of each analysed sweep: the two sections with the design beside them.
    const auto rows = sectionRows(s.scene->sections, s.scene->deltas);
    ASSERT_EQ(rows.size(), 2u);
    for (const SectionRow& r : rows) {
      ASSERT_TRUE(r.delta.has_value());
      // The sail flies as designed. 4 mm noise (SPEC §3) over a 3 m chord moves camber by a tenth of a
      // percent. The upper section, seen at 50° elevation with 0.1 m between lines (about 4,900 points
      // on the sail, 1.2 m chord), usually reads 0.3-0.4 % low (0.77-1.01 % before the smoothing's
      // radius was held to the sail's size), and twists 0.7° low. Sweeps whose sail took in the mast
      // read it 1.3-4.8 % off (CapturedDeckSweepsKeepTheMastOutOfTheSail below); since the mast is
      // found in them, 225 captured sweeps read it at most 0.52 % and 1.16° off.
      EXPECT_LT(std::abs(r.delta->camber_pct), 0.8) << "f " << r.fraction;
      EXPECT_LT(std::abs(r.delta->twist_deg), 1.5) << "f " << r.fraction;
    }
    EXPECT_FALSE(s.scene->surface.empty());
    // One unit's sweep: the outline moves the edges out by its LMS511 beam's footprint, 13 mm
    // across at the exit plus 4.7 mrad over the 5-10 m to the sail (SPEC §3): 1.8-3 cm.
    EXPECT_GT(s.scene->analysis->outline.footprint_reach_m, 0.015);
    EXPECT_LT(s.scene->analysis->outline.footprint_reach_m, 0.04);
    EXPECT_EQ(s.scene->cluster_deviation_m.size(), s.scene->analysis->sail_cloud.size());
    Database db = openSailDatabase(db_path);
    EXPECT_EQ(loadScanRecord(db, s.scan_id).sections.sections.size(), 2u) << "the analysis is stored with the sweep";
  }
  Database db = openSailDatabase(db_path);
  const CatalogTree tree = loadCatalogTree(db);
  EXPECT_EQ(tree.scan_count, stored);
  const TrimStepEntry* step = tree.stepOf(got.back().scan_id);
  ASSERT_NE(step, nullptr);
  EXPECT_EQ(step->sail, "main-A");
  EXPECT_EQ(step->step, 1);

  // Stopped means stopped: nothing more arrives, and it can start again.
  EXPECT_TRUE(live.take().empty());
  params.scene = good;
  params.save_to.clear();
  params.max_sweeps = 1;
  live.start(session, params);
  got = collect(live, [](const auto& v) { return !v.empty(); });
  live.stop();
  ASSERT_EQ(got.size(), 1u) << live.status().error;
  EXPECT_EQ(got[0].scan_id, 0) << "not stored without a database";
  EXPECT_EQ(live.status().swept, 1);
}

TEST(LiveMode, AUnitThatCannotSweepEndsLiveModeWithItsReason) {
  test::TempDir dir;
  UnitConfig u = quickDeckUnit();
  u.serial_device = dir.file("no-such-tty");
  ScannerSession session;
  session.units().push_back({u, "test", nullptr});
  LiveMode live;
  live.start(session, LiveParams{});
  const std::vector<LiveSweep> got = collect(live, [](const auto&) { return false; });
  EXPECT_TRUE(got.empty());
  EXPECT_FALSE(live.running());
  EXPECT_NE(live.status().error.find("sweep 1"), std::string::npos) << live.status().error;
  EXPECT_NE(live.status().error.find("no-such-tty"), std::string::npos) << live.status().error;
}

TEST(LiveMode, RefusesWhatItCannotDo) {
  LiveMode live;
  EXPECT_THROW(live.start(ScannerSession{}, LiveParams{}), InvalidInput);
  ScannerSession session;
  session.units().push_back({deckUnit(), "test", nullptr});
  test::TempDir dir;
  LiveParams missing_db;
  missing_db.save_to = dir.file("none.sqlite");
  EXPECT_THROW(live.start(session, missing_db), InvalidInput);
  LiveParams bad_controls;
  bad_controls.form.controls = "sheet";
  EXPECT_THROW(live.start(session, bad_controls), InvalidInput);
  LiveParams negative;
  negative.max_sweeps = -1;
  EXPECT_THROW(live.start(session, negative), InvalidInput);
  EXPECT_FALSE(live.running());

  EXPECT_THROW(sailRoi(Mesh{}), InvalidInput);
  EXPECT_THROW(sailRoi(deckMain(), -0.1), InvalidInput);
  EXPECT_THROW(sailRoi(deckMain(), 0.3, 50.0), InvalidInput) << "a deck above the head";
  EXPECT_THROW(designedSailParams(deckMain(), 0), InvalidInput);
  EXPECT_THROW(designedSailParams(deckMain(), 21), InvalidInput);
}

// Sweeps of the emulated deck unit, captured as live mode stored them (tests/viewer/data/README.md),
// each analysed as live mode does. The sail flies as designed. Both once went wrong at the mast,
// 6 m from the unit, which its fans, 6.4 cm apart there, cross in two or three lines:
// - deck-sweep-mast-in-sail.ply: the sail's region grew up the mast (up to 60 cm forward of the
//   upper luff); the spar search wanted 100° of its girth filled, which three lines never fill,
//   and found none. The sail kept about 120 of the mast's points; the upper section read 4.8 %
//   less camber and 2.3° less twist. (3 of 270 sweeps did this, by 1.3-4.8 %.)
// - deck-sweep-mast-tail.ply: once the mast was found, one of its points 2.9σ off the fitted
//   surface came back into the sail as a point of its surface, and the tack moved 30 cm up it.
TEST(LiveMode, CapturedDeckSweepsKeepTheMastOutOfTheSail) {
  const Mesh design = deckMain();
  const SailSurface sail(exampleDesign(SailType::Main));
  SceneOptions options;
  options.roi = sailRoi(design, 0.3);
  options.analysis = designedSailParams(design, 2);
  for (const char* name : {"deck-sweep-mast-in-sail.ply", "deck-sweep-mast-tail.ply"}) {
    SCOPED_TRACE(name);
    ScanRecord record;
    record.has_design = true;
    record.cloud = readCloud(std::string(SAILSHAPE_TEST_DATA) + "/" + name).cloud;
    const ScanScene scene = buildScanScene(std::move(record), design, options);
    ASSERT_TRUE(scene.analysis.has_value()) << scene.analysis_error;
    const SailAnalysis& a = *scene.analysis;
    // The mast: 9 cm radius, upright at (0.1, 0), 12 m tall.
    ASSERT_GE(a.spars.size(), 1u);
    const Spar& mast = a.spars[0].spar;
    EXPECT_NEAR(mast.radius_m, 0.09, 2 * options.analysis.sensor_sigma_m);
    EXPECT_GT(std::abs(mast.axis.z()), std::cos(1.0 * kRadPerDeg));
    for (const Vec3& x : a.sail_cloud.points)
      ASSERT_GT(distanceToSpar(x, mast), 2 * options.analysis.sensor_sigma_m) << "a point on the mast: " << x.transpose();
    // Corners within two samples' spacing (0.5° at 12 m is 10 cm).
    EXPECT_LT((a.outline.tack - sail.tack()).norm(), 0.2);
    EXPECT_LT((a.outline.clew - sail.clew()).norm(), 0.2);
    EXPECT_LT((a.outline.head - sail.head()).norm(), 0.2);
    ASSERT_EQ(scene.deltas.size(), 2u);
    for (const SectionDelta& d : scene.deltas) {
      // As the live-mode test above: the upper section usually reads 0.3-0.4 % camber and 0.7°
      // twist low in these sparse sweeps.
      EXPECT_LT(std::abs(d.delta.camber_pct), 0.7) << "f " << d.fraction;
      EXPECT_LT(std::abs(d.delta.twist_deg), 1.3) << "f " << d.fraction;
    }
  }
}

TEST(LiveMode, TheSailRoiIsTheDesignBoxAboveTheDeck) {
  const Mesh design = deckMain();
  const RoiBox roi = sailRoi(design, 0.3, 0.8);
  EXPECT_TRUE(roi.enabled);
  for (const Vec3& v : design.vertices) {
    EXPECT_TRUE((v.array() >= roi.min_m.array() + 0.3 - 1e-9).head<2>().all());
    EXPECT_TRUE((v.array() <= roi.max_m.array() - 0.3 + 1e-9).all());
  }
  EXPECT_DOUBLE_EQ(roi.min_m.z(), 0.8) << "the example main's foot sits at 1 m: the box stops at the deck limit";
  const AnalysisParams p = designedSailParams(design, 4);
  EXPECT_EQ(p.sections.count, 4);
  ASSERT_EQ(p.outline.design_lengths_m.size(), 3u);
  // The example main: luff 10 m, leech 10.5 m, foot 3.6 m (straight lengths; the edges are curved a little).
  EXPECT_NEAR(p.outline.design_lengths_m[0], 10.0, 0.2);
  EXPECT_NEAR(p.outline.design_lengths_m[1], 10.5, 0.2);
  EXPECT_NEAR(p.outline.design_lengths_m[2], 3.6, 0.2);
}

}  // namespace
}  // namespace sailshape::viewer
