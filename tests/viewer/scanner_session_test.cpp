// The scanner panel's model end to end: emulated units serve the real protocols
// (turntable on a pty, SICK CoLa on TCP), the scan is taken and saved to a
// database file with its trim-step data.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <cmath>
#include <fstream>

#include "acquisition/scene.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/design/sail_generator.hpp"
#include "database/scan_record.hpp"
#include "database/schema.hpp"
#include "viewer/catalog_tree.hpp"
#include "viewer/scanner_session.hpp"
#include "viewer_fixture.hpp"

namespace sailshape::viewer {
namespace {

constexpr double kSigmaCloth = 0.0041;  // SPEC §3, sail cloth

Scene wallAt(double y) {
  Scene s;
  s.objects.push_back({"wall", Material::Cloth, makeQuad(Vec3(-20, y, -20), Vec3(20, y, -20), Vec3(20, y, 20), Vec3(-20, y, 20))});
  return s;
}

// A short sweep: 1° beams, α 60°..120°, β −15°..+15° at 30 °/s.
UnitConfig compactUnit() {
  UnitConfig u;
  u.name = "wall-unit";
  u.frequency_hz = 50;
  u.resolution_deg = 1.0;
  u.output_start_deg = 60;
  u.output_stop_deg = 120;
  u.start_angle_deg = -15;
  u.sweep_angle_deg = 30;
  u.speed_deg_s = 30;
  u.acceleration_deg_s2 = 300;
  return u;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(ScannerSession, AnEmulatedScanReachesTheDatabaseWithItsTrimStep) {
  ScannerSession session;
  session.addEmulatedUnit(wallAt(3.0), "wall", compactUnit());
  ASSERT_EQ(session.units().size(), 1u);
  EXPECT_EQ(session.units()[0].origin, "emulated (wall)");
  EXPECT_NE(session.units()[0].config.port, 0);

  const Acquisition a = session.scan();
  ASSERT_EQ(a.sweeps.size(), 1u);
  EXPECT_FALSE(a.sweeps[0].partial) << a.sweeps[0].message;
  // 30° of turntable at 50 Hz and 30 °/s: about 50 scans of 61 beams.
  ASSERT_GT(a.cloud.size(), 1000u);
  std::vector<double> off;
  for (const Vec3& p : a.cloud.points) off.push_back(std::abs(p.y() - 3.0));
  EXPECT_LT(median(off), 2 * kSigmaCloth) << "the points lie on the wall";
  EXPECT_LT(*std::max_element(off.begin(), off.end()), 0.1);

  test::TempDir dir;
  Database db = openSailDatabase(dir.file("scan.sqlite"));
  TrimStepForm form;
  form.campaign = "Wind tunnel";
  form.sail = "main-A";
  form.test = "upwind";
  form.step = 2;
  form.awa_deg = 28.0;
  form.drive_n = 120.0;
  form.side_n = 300.0;
  form.controls = "sheet=0.42; traveller=-0.1";
  const ImportResult saved = saveAcquisition(db, a, form);

  const CatalogTree tree = loadCatalogTree(db);
  ASSERT_EQ(tree.scan_count, 1u);
  const TrimStepEntry* step = tree.stepOf(saved.scan_id);
  ASSERT_NE(step, nullptr);
  EXPECT_EQ(tree.campaigns[0].name, "Wind tunnel");
  EXPECT_EQ(tree.campaigns[0].tests[0].name, "upwind");
  EXPECT_EQ(step->step, 2);
  EXPECT_EQ(step->sail, "main-A");
  EXPECT_DOUBLE_EQ(*step->awa_deg, 28.0);
  EXPECT_DOUBLE_EQ(*step->drive_n, 120.0);
  EXPECT_EQ(step->controls.find("sheet=0.42") != std::string::npos, true) << step->controls;
  const ScanRecord r = loadScanRecord(db, saved.scan_id);
  ASSERT_TRUE(r.cloud.has_value());
  ASSERT_EQ(r.cloud->size(), a.cloud.size());
  EXPECT_NEAR(r.cloud->points[10].y(), a.cloud.points[10].y(), 1e-5);  // float32 in the blob
}

TEST(ScannerSession, TheDeckUnitSeesTheMainsail) {
  ScannerSession session;
  UnitConfig unit = deckUnit();
  unit.speed_deg_s = 60;  // a quicker sweep for the test
  unit.acceleration_deg_s2 = 600;
  unit.resolution_deg = 1.0;
  session.addEmulatedUnit(builtInDeckScene(), "deck", unit);
  const Acquisition a = session.scan();
  ASSERT_GT(a.cloud.size(), 1000u);
  // The built-in deck's mainsail is the example design; a good share of what the unit sees is sail.
  const DesignDistance sail(generateSailMesh(exampleDesign(SailType::Main)));
  size_t on_sail = 0;
  for (const Vec3& p : a.cloud.points)
    if (std::abs(sail.signedDistance(p)) < 5 * kSigmaCloth) ++on_sail;
  EXPECT_GT(on_sail, a.cloud.size() / 5) << on_sail << " of " << a.cloud.size();
  // One unit's sweep keeps where it stood and each sample's scan angles, which its
  // mixed pixels are found by.
  ASSERT_TRUE(a.cloud.viewpoint.has_value());
  ASSERT_TRUE(a.cloud.hasScanAngles());
  EXPECT_EQ(a.cloud.alpha_rad.size(), a.cloud.size());
  EXPECT_EQ(a.cloud.beta_rad.size(), a.cloud.size());
}

TEST(ScannerSession, TheCloudArrivesWhileTheUnitsSweep) {
  // Two units, so the scan lines come from two sweeping threads at once.
  ScannerSession session;
  session.addEmulatedUnit(wallAt(3.0), "wall", compactUnit());
  UnitConfig second = compactUnit();
  second.name = "wall-unit-2";
  session.addEmulatedUnit(wallAt(3.0), "wall", second);
  ArrivingPoints arriving;
  auto scan = std::async(std::launch::async, [&] { return session.scan(arriving.feeding()); });
  // The UI's view of it: poll as the render loop does, and count the times it grew.
  uint64_t seen = 0;
  size_t growths = 0, shown = 0;
  while (scan.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
    if (auto pts = arriving.newerThan(seen)) {
      if (pts->size() > shown) ++growths;
      shown = pts->size();
    }
  }
  const Acquisition a = scan.get();
  ASSERT_EQ(a.sweeps.size(), 2u);
  ASSERT_GT(a.cloud.size(), 0u);
  // The 1 s sweeps at 30 °/s were seen growing many times before the scan returned.
  EXPECT_GE(growths, 5u);
  EXPECT_GT(shown, 0u);
  // In the end every point of the scan was shown (and those at the start angle before the move).
  auto all = arriving.newerThan(seen);
  const size_t total = all ? all->size() : shown;
  EXPECT_GE(total, a.cloud.size());
  // Nothing new: nothing returned.
  EXPECT_FALSE(arriving.newerThan(seen).has_value());
  arriving.clear();
  auto cleared = arriving.newerThan(seen);
  ASSERT_TRUE(cleared.has_value());
  EXPECT_TRUE(cleared->empty());
}

TEST(ScannerSession, HomesAnEmulatedTurntable) {
  ScannerSession session;
  session.addEmulatedUnit(wallAt(3.0), "wall", compactUnit());
  EXPECT_NO_THROW(session.home(0, 30));
  EXPECT_THROW(session.home(1), InvalidInput);
}

TEST(ScannerSession, RefusesWhatItCannotDo) {
  ScannerSession session;
  EXPECT_THROW(session.scan(), InvalidInput);
  EXPECT_THROW(session.removeUnit(0), InvalidInput);
  test::TempDir dir;
  EXPECT_THROW(session.addUnitFile(dir.file("missing.json")), FileError);
  EXPECT_TRUE(session.units().empty());

  Database db = openSailDatabase(dir.file("s.sqlite"));
  EXPECT_THROW(saveAcquisition(db, Acquisition{}, TrimStepForm{}), InvalidInput);
  Acquisition one;
  one.cloud.points = {Vec3(0, 3, 1)};
  TrimStepForm bad;
  bad.controls = "sheet=loose";
  EXPECT_THROW(saveAcquisition(db, one, bad), InvalidInput);
  EXPECT_EQ(loadCatalogTree(db).scan_count, 0u) << "a refused scan leaves nothing behind";
}

TEST(ScannerSession, ParsesControlSettings) {
  const auto c = parseControls("sheet=0.42; traveller = -0.1, vang=3");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_DOUBLE_EQ(c.at("sheet"), 0.42);
  EXPECT_DOUBLE_EQ(c.at("traveller"), -0.1);
  EXPECT_DOUBLE_EQ(c.at("vang"), 3.0);
  EXPECT_TRUE(parseControls("  ").empty());
  EXPECT_THROW(parseControls("sheet"), InvalidInput);
  EXPECT_THROW(parseControls("=3"), InvalidInput);
  EXPECT_THROW(parseControls("sheet=0.4x"), InvalidInput);
}

TEST(ScannerSession, UnitFilesLoadIntoSlots) {
  test::TempDir dir;
  const std::string path = dir.file("unit.json");
  UnitConfig u = compactUnit();
  u.name = "bow";
  u.pose = makePose(Vec3(1, 2, 3), 0, 0, 90 * kRadPerDeg);
  std::ofstream(path) << unitToJson(u);
  ScannerSession session;
  session.addUnitFile(path);
  ASSERT_EQ(session.units().size(), 1u);
  EXPECT_EQ(session.units()[0].config.name, "bow");
  EXPECT_EQ(session.units()[0].origin, path);
  EXPECT_EQ(session.units()[0].emulator, nullptr);
  session.removeUnit(0);
  EXPECT_TRUE(session.units().empty());
}

}  // namespace
}  // namespace sailshape::viewer
