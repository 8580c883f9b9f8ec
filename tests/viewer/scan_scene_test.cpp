#include <gtest/gtest.h>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/pipeline/sail_region.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/scan_record.hpp"
#include "viewer/scan_scene.hpp"
#include "viewer/worker.hpp"
#include "viewer_fixture.hpp"

namespace sailshape::viewer {
namespace {

// The flying shape is the design with camber +2 % and twist +3° at every station
// (viewer_fixture.hpp); the scene must find those differences within the
// 1σ uncertainties the pipeline derives from the 4 mm sensor noise.
TEST(ScanScene, FindsTheKnownTrimAgainstTheDesign) {
  test::TempDir dir;
  const std::string path = dir.file("s.sqlite");
  test::makeSailDatabase(path, 1);
  Database db = openSailDatabase(path);
  ScanRecord record = loadScanRecord(db, 1);
  ASSERT_TRUE(record.has_design);
  const Mesh design = sailDesignMesh(db, record.sail);

  const ScanScene scene = buildScanScene(record, design);
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  ASSERT_TRUE(scene.analysis.has_value());
  EXPECT_FALSE(scene.surface.empty());
  EXPECT_EQ(scene.surface_deviation_m.size(), scene.surface.vertices.size());
  EXPECT_EQ(scene.raw_deviation_m.size(), scene.raw_cloud.size());
  EXPECT_EQ(scene.raw_cloud.size(), 20'000u);
  ASSERT_EQ(scene.sections.sections.size(), 3u);
  ASSERT_EQ(scene.deltas.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const SectionDelta& d = scene.deltas[k];
    const SectionParameters& u = scene.sections.sections[k].uncertainty;
    EXPECT_NEAR(d.delta.camber_pct, 2.0, 3 * u.camber_pct + 0.1) << "section " << k;
    EXPECT_NEAR(d.delta.twist_deg, 3.0, 3 * u.twist_deg + 0.2) << "section " << k;
    EXPECT_DOUBLE_EQ(d.flying.camber_pct, scene.sections.sections[k].value.camber_pct)
        << "the table shows the stored sections";
  }
  // More camber and more twist both move the flying shape to leeward of the design.
  ASSERT_TRUE(scene.deviation.has_value());
  EXPECT_GT(scene.deviation->mean_m, 0.0);
  EXPECT_GT(scene.deviation->p5_m, -3 * test::kSensorSigmaM);
  // Camber +2 % and twist +3° are a plausible trim: no mismatch to show in red.
  EXPECT_EQ(scene.design_mismatch, "");
}

// The same scan against its design grown 1.3× about the tack: area and edges beyond
// a plausible trim (±20 %, ±10 %), a message the viewer shows in red.
TEST(ScanScene, ASailFarFromItsDesignGivesTheMismatch) {
  test::TempDir dir;
  const std::string path = dir.file("s.sqlite");
  test::makeSailDatabase(path, 1);
  Database db = openSailDatabase(path);
  const ScanRecord record = loadScanRecord(db, 1);
  Mesh design = sailDesignMesh(db, record.sail);
  Eigen::AlignedBox3d box;
  for (const Vec3& v : design.vertices) box.extend(v);
  const Vec3 tack(box.max().x(), box.center().y(), box.min().z());
  for (Vec3& v : design.vertices) v = tack + 1.3 * (v - tack);
  const ScanScene scene = buildScanScene(record, design);
  EXPECT_NE(scene.design_mismatch.find("area"), std::string::npos) << scene.design_mismatch;
}

// A scan of two sails stored with the main's region: the viewer analyses the main
// (within the noise of its design), where the whole cloud gives the larger gennaker.
TEST(ScanScene, AStoredRegionKeepsTheAnalysisOnItsSail) {
  const SailDesign main = exampleDesign(SailType::Main), a2 = exampleDesign(SailType::Gennaker);
  ScanSimulation sim;
  sim.noise_sigma_m = test::kSensorSigmaM;
  sim.points = 15'000;
  Cloud scan = sampleSail(main, sim);
  sim.seed = 2;
  sim.points = 30'000;
  const Cloud other = sampleSail(a2, sim);
  scan.points.insert(scan.points.end(), other.points.begin(), other.points.end());
  scan.viewpoint.reset();  // sampled apart: neither shadows the other
  const Mesh design = generateSailMesh(main);
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("r.sqlite"));
  addDesignVersion(db, "Main", design, {});
  ImportMetadata m;
  m.sail = "Main";
  m.region = ScanRegion{designRegion(design, plausibleTrimDeviationM(design)), 1};
  const ScanRecord record = loadScanRecord(db, importScan(db, m, nullptr, &scan).scan_id);
  const ScanScene scene = buildScanScene(record, design);
  ASSERT_TRUE(scene.deviation.has_value()) << scene.analysis_error;
  EXPECT_LT(scene.deviation->rms_m, 3 * test::kSensorSigmaM);
  EXPECT_EQ(scene.design_mismatch, "");
  ScanRecord whole = record;
  whole.region.reset();
  const ScanScene wrong = buildScanScene(whole, design);
  ASSERT_TRUE(wrong.deviation.has_value()) << wrong.analysis_error;
  EXPECT_GT(wrong.deviation->rms_m, plausibleTrimDeviationM(design));
  EXPECT_NE(wrong.design_mismatch, "");
}

TEST(ScanScene, WithoutDesignOrCloudItSaysWhatIsMissing) {
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  const auto doc = nlohmann::json{{"sections", nlohmann::json::array({{{"fraction", 0.5}, {"camber_pct", 11.0}}})}};
  ImportMetadata meta;
  const ImportResult r = importScan(db, meta, &doc);
  const ScanScene scene = buildScanScene(loadScanRecord(db, r.scan_id), std::nullopt);
  EXPECT_TRUE(scene.raw_cloud.empty());
  EXPECT_TRUE(scene.surface.empty());
  EXPECT_FALSE(scene.deviation.has_value());
  EXPECT_TRUE(scene.deltas.empty());
  ASSERT_EQ(scene.sections.sections.size(), 1u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("no stored cloud"), std::string::npos);
}

// The surface stored with the analysis is the one its sections were cut from: the scene shows
// it and measures the deviation on it, even where a re-analysis of the cloud fails.
TEST(ScanScene, TheStoredSurfaceIsShownAndMeasured) {
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("s.sqlite"));
  const SailDesign design = exampleDesign(SailType::Main);
  const Mesh design_mesh = generateSailMesh(design);
  const Mesh flying = generateSailMesh(test::trimmed(2.0, 3.0));
  const auto doc = nlohmann::json{{"sections", nlohmann::json::array({{{"fraction", 0.5}, {"camber_pct", 13.0}}})}};
  Cloud two_points;
  two_points.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};  // a re-analysis fails on it
  ImportMetadata meta;
  const ImportResult r = importScan(db, meta, &doc, &two_points, {}, &flying);
  const ScanScene scene = buildScanScene(loadScanRecord(db, r.scan_id), design_mesh);
  ASSERT_EQ(scene.surface.vertices.size(), flying.vertices.size());
  EXPECT_EQ(scene.surface.triangles, flying.triangles);
  ASSERT_EQ(scene.surface_deviation_m.size(), flying.vertices.size());
  ASSERT_TRUE(scene.deviation.has_value());
  // +2 % camber and +3° twist put the whole surface to leeward of the design; the stored
  // vertices are exact, so no point lies to windward beyond the distance's own error.
  EXPECT_GT(scene.deviation->mean_m, 0.0);
  EXPECT_GT(scene.deviation->p5_m, -0.001);
  ASSERT_FALSE(scene.warnings.empty());
  EXPECT_NE(scene.warnings[0].find("sail cluster: the pipeline failed"), std::string::npos) << scene.warnings[0];
}

TEST(ScanScene, APipelineFailureBecomesAWarning) {
  ScanRecord record;
  record.cloud = Cloud{};
  record.cloud->points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};  // too few points for any surface
  const ScanScene scene = buildScanScene(record, std::nullopt);
  EXPECT_TRUE(scene.surface.empty());
  ASSERT_FALSE(scene.warnings.empty());
  EXPECT_NE(scene.warnings[0].find("pipeline failed"), std::string::npos);
  EXPECT_EQ(scene.raw_cloud.size(), 2u);
}

TEST(ScanScene, CancelUnwindsThroughTheProgressCallback) {
  test::TempDir dir;
  const std::string path = dir.file("s.sqlite");
  test::makeSailDatabase(path, 1);
  Database db = openSailDatabase(path);
  Progress cancel;
  cancel.callback = [](std::string_view, double) { throw Cancelled(); };
  EXPECT_THROW(buildScanScene(loadScanRecord(db, 1), std::nullopt, {}, cancel), Cancelled);
}

TEST(ScanScene, ThinCloudKeepsEveryKthPoint) {
  Cloud c;
  for (int i = 0; i < 10; ++i) c.points.emplace_back(i, 0, 0);
  const Cloud t = thinCloud(c, 4);
  ASSERT_EQ(t.size(), 4u);  // step 3: 0, 3, 6, 9
  EXPECT_DOUBLE_EQ(t.points[3].x(), 9.0);
  EXPECT_EQ(thinCloud(c, 10).size(), 10u);
  EXPECT_THROW(thinCloud(c, 0), InvalidInput);
}

}  // namespace
}  // namespace sailshape::viewer
