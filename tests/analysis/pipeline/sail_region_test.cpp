// The sail a scan was taken of: its region, the cluster that matches its design, and
// the check that what was found flies as that design could.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/pipeline/sail_region.hpp"

namespace sailshape {
namespace {

uint64_t testSeed() {
  const char* fixed = std::getenv("SAILSHAPE_TEST_SEED");
  const uint64_t seed = fixed ? std::strtoull(fixed, nullptr, 10) : std::random_device{}();
  std::printf("seed %llu (SAILSHAPE_TEST_SEED replays it)\n", static_cast<unsigned long long>(seed));
  return seed;
}

Cloud concat(const Cloud& a, const Cloud& b) {
  Cloud out = a;
  out.points.insert(out.points.end(), b.points.begin(), b.points.end());
  return out;
}

// A 2 m × 10 m flat panel (two triangles): area / height = 2 m, so the bound is 0.4 m.
TEST(SailRegion, PlausibleTrimIsAFifthOfTheMeanChord) {
  Mesh panel;
  panel.vertices = {Vec3(0, 0, 0), Vec3(-2, 0, 0), Vec3(-2, 0, 10), Vec3(0, 0, 10)};
  panel.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_NEAR(plausibleTrimDeviationM(panel), 0.4, 1e-12);
  Mesh flat = panel;
  for (Vec3& v : flat.vertices) v.z() = 0;
  EXPECT_THROW(plausibleTrimDeviationM(flat), InvalidInput);
  const RegionBox box = designRegion(panel, 0.4);
  EXPECT_TRUE(box.min().isApprox(Vec3(-2.4, -0.4, -0.4)));
  EXPECT_TRUE(box.max().isApprox(Vec3(0.4, 0.4, 10.4)));
  EXPECT_THROW(designRegion(panel, -1), InvalidInput);
  EXPECT_THROW(designRegion(panel, std::nan("")), InvalidInput);
}

TEST(SailRegion, ABoxIsSixFiniteNumbersMinBeforeMax) {
  const RegionBox box = parseRegionBox("-1.5,0.25,-1,1,0,12");
  EXPECT_TRUE(box.min().isApprox(Vec3(-1.5, -1, 0)));
  EXPECT_TRUE(box.max().isApprox(Vec3(0.25, 1, 12)));
  EXPECT_EQ(formatRegionBox(box), "-1.500,0.250,-1.000,1.000,0.000,12.000");
  for (const char* bad : {"1,0,0,1,0,1", "0,1,0,1,2,1", "nan,1,0,1,0,1", "0,inf,0,1,0,1", "0,1,0,1,0", "0,1,0,1,0,1,2",
                          "a,1,0,1,0,1", "0,1,,1,0,1", ""})
    EXPECT_THROW(parseRegionBox(bad), InvalidInput) << bad;
}

TEST(SailRegion, CropKeepsTheScansViewpointAndRangeAndRefusesAnEmptyRegion) {
  Cloud cloud;
  cloud.points = {Vec3(0, 0, 1), Vec3(5, 0, 1), Vec3(0.5, 0.5, 2)};
  cloud.intensity = {1, 2, 3};
  cloud.viewpoint = Vec3(-3, -4, 1);
  cloud.scanner_range_m = 20;
  const Cloud in = cropToRegion(cloud, parseRegionBox("-1,1,-1,1,0,3"));
  ASSERT_EQ(in.size(), 2u);
  EXPECT_FLOAT_EQ(in.intensity[1], 3.0f);
  ASSERT_TRUE(in.viewpoint.has_value());
  EXPECT_TRUE(in.viewpoint->isApprox(Vec3(-3, -4, 1)));
  EXPECT_EQ(in.scanner_range_m, 20);
  EXPECT_THROW(cropToRegion(cloud, parseRegionBox("10,11,0,1,0,1")), AnalysisError);
}

TEST(SailRegion, DesignPointsFillLargeTrianglesToTheSpacing) {
  Mesh tri;
  tri.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
  tri.triangles = {{0, 1, 2}};
  const std::vector<Vec3> pts = designSurfacePoints(tri, 0.1);
  // The triangle's centroid lies within a grid step (0.1 m × √2 / 2 by the hypotenuse) of a point.
  double nearest = 1e9;
  for (const Vec3& p : pts) nearest = std::min(nearest, (p - Vec3(1.0 / 3, 0, 1.0 / 3)).norm());
  EXPECT_LT(nearest, 0.1);
  EXPECT_GE(pts.size(), 66u);  // (n + 1)(n + 2) / 2 with n = ceil(√2 / 0.1) = 15, plus the vertices
}

// Two sails in one scan: the gennaker has twice the points, so "auto" takes it; guided
// by the main's design, the analysis takes the main and finds it on its design.
TEST(SailRegion, TheDesignPicksItsSailWhereTheLargestClusterIsAnother) {
  const uint64_t seed = testSeed();
  const SailDesign main = exampleDesign(SailType::Main), a2 = exampleDesign(SailType::Gennaker);
  ScanSimulation sim;
  sim.noise_sigma_m = 0.004;
  sim.seed = seed;
  sim.points = 15'000;
  const Cloud main_cloud = sampleSail(main, sim);
  sim.seed = seed + 1;
  sim.points = 30'000;
  Cloud scan = concat(main_cloud, sampleSail(a2, sim));
  // Each sail was sampled as if the other were not there: no viewpoint, or the
  // gennaker would read as a shadow over the main's clew.
  scan.viewpoint.reset();
  const Mesh main_mesh = generateSailMesh(main);

  AnalysisParams guided;
  guideByDesign(guided, main_mesh);
  const SailAnalysis a = analyzeSail(scan, guided);
  // Every point the analysis kept lies on the main: within 4σ of the sensor noise (and
  // the smoothing's displacement) of its design, none a gennaker's.
  const DesignDistance distance(main_mesh);
  const DistanceStats st = distanceStats(signedDistances(distance, a.sail_cloud.points));
  EXPECT_LT(st.max_abs_m, 4 * 0.004 + 0.01);
  EXPECT_NEAR(a.outline.area_m2, meshArea(main_mesh), 0.05 * meshArea(main_mesh));

  const SailAnalysis unguided = analyzeSail(scan, AnalysisParams{});
  EXPECT_GT(distanceStats(signedDistances(distance, unguided.sail_cloud.points)).rms_m, plausibleTrimDeviationM(main_mesh))
      << "without the design the largest sail-like cluster (the gennaker) is picked";
}

TEST(SailRegion, AScanWithoutTheSailIsRefusedInOneLine) {
  ScanSimulation sim;
  sim.seed = testSeed();
  sim.points = 20'000;
  const Cloud a2 = sampleSail(exampleDesign(SailType::Gennaker), sim);
  Mesh far = generateSailMesh(exampleDesign(SailType::Main));
  for (Vec3& v : far.vertices) v.x() -= 30;  // 30 m aft: nothing of the gennaker near it
  AnalysisParams p;
  guideByDesign(p, far);
  try {
    analyzeSail(a2, p);
    ADD_FAILURE() << "analysed a scan without its sail";
  } catch (const AnalysisError& e) {
    EXPECT_NE(std::string(e.what()).find("of the sail's design"), std::string::npos) << e.what();
  }
}

// A plausible trim (camber +3 %, twist +5° at every station) flies within the bounds;
// the same analysis against another sail's design, or its own scaled 1.3×, does not.
TEST(SailRegion, AMismatchIsToldAndAPlausibleTrimIsNot) {
  const SailDesign design = exampleDesign(SailType::Main);
  SailDesign flying = design;
  for (ProfileStation& s : flying.stations) s.camber_pct += 3, s.twist_deg += 5;
  ScanSimulation sim;
  sim.seed = testSeed();
  sim.noise_sigma_m = 0.004;
  sim.points = 30'000;
  const SailAnalysis a = analyzeSail(sampleSail(flying, sim), AnalysisParams{});
  auto mismatch = [&](const Mesh& d) {
    const MeshSections ds = analyzeMeshSections(d);
    const DesignComparison c = compareWithDesign(d, ds.sections, a.sail_cloud.points, a.sections);
    return designMismatch(d, ds, a, c.stats);
  };
  const Mesh own = generateSailMesh(design);
  EXPECT_EQ(mismatch(own), "");
  const std::string other = mismatch(generateSailMesh(exampleDesign(SailType::Gennaker)));
  EXPECT_NE(other.find("RMS deviation"), std::string::npos) << other;
  const std::string scaled = mismatch(generateSailMesh(scaleDesign(design, 1.3)));
  EXPECT_NE(scaled.find("area"), std::string::npos) << scaled;
  EXPECT_NE(scaled.find("luff"), std::string::npos) << scaled;
}

}  // namespace
}  // namespace sailshape
