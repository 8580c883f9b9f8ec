#include <gtest/gtest.h>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "database/scan_record.hpp"
#include "viewer/processing.hpp"
#include "tests/support/footprint_scan.hpp"
#include "acquisition/unit_config.hpp"
#include "viewer_fixture.hpp"

namespace sailshape::viewer {
namespace {

Cloud lineX(int n) {
  Cloud c;
  for (int i = 0; i < n; ++i) c.points.emplace_back(i, 0, 0);
  return c;
}

TEST(Processing, CropKeepsThePointsInsideTheBox) {
  RoiBox roi;
  roi.enabled = true;
  roi.min_m = Vec3(2.5, -1, -1);
  roi.max_m = Vec3(6.5, 1, 1);
  const Cloud out = cropToBox(lineX(10), roi);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_DOUBLE_EQ(out.points.front().x(), 3.0);
  EXPECT_DOUBLE_EQ(out.points.back().x(), 6.0);
  roi.enabled = false;
  EXPECT_EQ(cropToBox(lineX(10), roi).size(), 10u);
}

TEST(Processing, CropRefusesAnInvertedOrEmptyBox) {
  RoiBox roi;
  roi.enabled = true;
  roi.min_m = Vec3(0, 2, 0);
  roi.max_m = Vec3(1, 1, 1);
  EXPECT_THROW(cropToBox(lineX(3), roi), InvalidInput);
  roi.min_m = Vec3(20, -1, -1);
  roi.max_m = Vec3(30, 1, 1);
  EXPECT_THROW(cropToBox(lineX(3), roi), AnalysisError);
}

TEST(Processing, TransformRotatesThenTranslates) {
  Cloud c = lineX(2);
  c.viewpoint = Vec3(1, 0, 0);
  CloudTransform t;
  t.yaw_deg = 90;
  t.translation_m = Vec3(0, 0, 5);
  EXPECT_FALSE(t.identity());
  const Cloud out = transformCloud(c, t);
  EXPECT_TRUE(out.points[1].isApprox(Vec3(0, 1, 5), 1e-12));
  EXPECT_TRUE(out.viewpoint->isApprox(Vec3(0, 1, 5), 1e-12));
  EXPECT_TRUE(CloudTransform{}.identity());
}

TEST(Processing, NormalsStageGivesCurvaturePerPoint) {
  ScanSimulation sim;
  sim.points = 5000;
  sim.noise_sigma_m = test::kSensorSigmaM;
  const Cloud cloud = sampleSail(exampleDesign(SailType::Main), sim);
  const StageResult r = runStages(cloud, {}, ProcessingStage::Normals);
  EXPECT_EQ(r.scalar_name, "curvature");
  ASSERT_EQ(r.scalar.size(), r.cloud.size());
  // The Filters stage ran before: 4 mm noise leaves few outliers to remove.
  EXPECT_LE(r.cloud.size(), cloud.size());
  EXPECT_GT(r.cloud.size(), cloud.size() * 95 / 100);
  for (double c : r.scalar) {
    EXPECT_GE(c, 0.0);
    EXPECT_LE(c, 1.0 / 3.0 + 1e-12);
  }
  EXPECT_FALSE(r.analysis.has_value());
}

TEST(Processing, SegmentationStageFindsTheSailInAScene) {
  ScanSimulation sim;
  sim.points = 20'000;
  sim.noise_sigma_m = test::kSensorSigmaM;
  const SceneCloud scene = sampleSailScene(exampleDesign(SailType::Main), sim);
  ProcessingParams params;
  params.analysis.statistical_outliers = false;  // keep the points' order to compare with is_sail
  params.analysis.radius_outliers = false;
  const StageResult r = runStages(scene.cloud, params, ProcessingStage::Segmentation);
  EXPECT_EQ(r.scalar_name, "cluster");
  ASSERT_EQ(r.scalar.size(), scene.cloud.size());
  // Most sail points share one cluster, and that cluster holds few non-sail points.
  std::map<int, size_t> sail_votes;
  for (size_t i = 0; i < r.scalar.size(); ++i)
    if (scene.is_sail[i]) ++sail_votes[static_cast<int>(r.scalar[i])];
  const auto best = std::max_element(sail_votes.begin(), sail_votes.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  ASSERT_NE(best->first, -1);
  size_t sail_points = 0, others_in_it = 0;
  for (size_t i = 0; i < r.scalar.size(); ++i) {
    sail_points += scene.is_sail[i] ? 1 : 0;
    if (!scene.is_sail[i] && static_cast<int>(r.scalar[i]) == best->first) ++others_in_it;
  }
  EXPECT_GT(best->second, sail_points * 8 / 10);
  EXPECT_LT(others_in_it, sail_points / 20);
}

TEST(Processing, SectionsStageMeasuresTheKnownSailAndSavesIt) {
  const SailDesign design = exampleDesign(SailType::Main);
  ScanSimulation sim;
  sim.points = 20'000;
  sim.noise_sigma_m = test::kSensorSigmaM;
  const Cloud cloud = sampleSail(design, sim);
  ProcessingParams params;
  params.analysis.segment = false;
  const StageResult r = runStages(cloud, params, ProcessingStage::Sections);
  ASSERT_TRUE(r.analysis.has_value());
  const SailSurface truth(design);
  ASSERT_EQ(r.analysis->sections.sections.size(), 3u);
  for (const Section& s : r.analysis->sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 3 * s.uncertainty.camber_pct + 0.1) << "f " << s.fraction;
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 3 * s.uncertainty.twist_deg + 0.2) << "f " << s.fraction;
  }

  test::TempDir dir;
  const std::string path = dir.file("p.sqlite");
  test::makeSailDatabase(path, 1);
  Database db = openSailDatabase(path);
  const int64_t before = loadScanRecord(db, 1).analysis_id;
  const int64_t id = saveStageResult(db, 1, r, params);
  EXPECT_GT(id, before);
  const ScanRecord back = loadScanRecord(db, 1);
  EXPECT_EQ(back.analysis_id, id);
  ASSERT_EQ(back.sections.sections.size(), 3u);
  EXPECT_NEAR(back.sections.sections[1].value.camber_pct, r.analysis->sections.sections[1].value.camber_pct, 1e-9);
  EXPECT_FALSE(back.analysis_params["segment"].get<bool>());
}

TEST(Processing, AStoredScanIsReanalysedWithItsUnitsBeam) {
  // An LMS511's scan of a flat main that stops short of every edge by the beam's
  // footprint, stored with its unit's settings as a sweep stores them.
  const ScannerSpec spec = scannerSpec(ScannerModel::Lms511);
  const Cloud cloud = test::scanWithFootprint(40000, 7, spec.exit_diameter_m, spec.beam_divergence_rad);
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("p.sqlite"));
  UnitConfig unit;
  unit.model = ScannerModel::Lms511;
  ImportMetadata meta;
  meta.sail = "main-A";
  meta.test = "upwind";
  meta.trim_step = 1;
  meta.settings = nlohmann::json::parse(unitToJson(unit));
  const int64_t scan = importScan(db, meta, nullptr, &cloud).scan_id;
  meta.trim_step = 2;
  meta.settings = nullptr;  // a cloud imported from a file: no unit known
  const int64_t unknown = importScan(db, meta, nullptr, &cloud).scan_id;

  const ScanRecord record = loadScanRecord(db, scan);
  ASSERT_TRUE(record.cloud && record.cloud->viewpoint);
  EXPECT_EQ(*record.cloud->viewpoint, test::kScanner);
  ProcessingParams params;
  params.analysis.segment = false;
  params.analysis.sensor_sigma_m = 0.001;  // noise-free samples
  EXPECT_EQ(useScanBeam(params, record), "lms511");
  EXPECT_EQ(params.analysis.outline.beam_exit_diameter_m, spec.exit_diameter_m);
  EXPECT_EQ(params.analysis.outline.beam_divergence_rad, spec.beam_divergence_rad);
  const StageResult r = runStages(*record.cloud, params, ProcessingStage::Sections);
  ASSERT_TRUE(r.analysis.has_value());
  // Issue 2's corner target, as the first analysis with the beam reaches it
  // (tests/analysis/beam_footprint_test.cpp); uncorrected the head is 10 cm and more low.
  EXPECT_LT((r.analysis->outline.head - test::kHead).norm(), 0.03);
  EXPECT_LT((r.analysis->outline.tack - test::kTack).norm(), 0.03);
  EXPECT_NEAR(r.analysis->outline.luff_length_m, (test::kHead - test::kTack).norm(), 0.01);
  bool said = false;
  for (const std::string& line : r.summary) said |= line.rfind("edges moved out by the beam's footprint, ", 0) == 0;
  EXPECT_TRUE(said);

  // A beam set by hand stays; no unit, or no viewpoint, sets none.
  ProcessingParams own;
  own.analysis.outline.beam_exit_diameter_m = 0.02;
  EXPECT_EQ(useScanBeam(own, record), "");
  EXPECT_EQ(own.analysis.outline.beam_exit_diameter_m, 0.02);
  EXPECT_EQ(own.analysis.outline.beam_divergence_rad, 0.0);
  ProcessingParams none;
  EXPECT_EQ(useScanBeam(none, loadScanRecord(db, unknown)), "");
  EXPECT_EQ(none.analysis.outline.beam_exit_diameter_m, 0.0);
  ScanRecord blind = record;
  blind.cloud->viewpoint.reset();
  EXPECT_EQ(useScanBeam(none, blind), "");
  EXPECT_EQ(none.analysis.outline.beam_divergence_rad, 0.0);
}

TEST(Processing, RefusesWhatItCannotDo) {
  EXPECT_THROW(runStages(Cloud{}, {}, ProcessingStage::Roi), InvalidInput);
  test::TempDir dir;
  Database db = openSailDatabase(dir.file("p.sqlite"));
  const StageResult roi = runStages(lineX(5), {}, ProcessingStage::Roi);
  EXPECT_EQ(roi.cloud.size(), 5u);
  EXPECT_THROW(saveStageResult(db, 1, roi, {}), InvalidInput);
  EXPECT_STREQ(stageName(ProcessingStage::Segmentation), "Segmentation");
  EXPECT_EQ(allStages().size(), 7u);
}

}  // namespace
}  // namespace sailshape::viewer
