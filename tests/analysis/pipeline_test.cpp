// The whole analysis on synthetic sails whose section parameters are known by
// construction (analysis/sail_generator), in the tolerances of the core issue.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/errors.hpp"
#include "analysis/pipeline.hpp"
#include "analysis/sail_generator.hpp"

namespace sailshape {
namespace {

struct Tolerance {
  double camber_pct, draft_pct, twist_deg, end_deg, corner_m;
};
// Clean data: the targets (camber 0.1 % of chord, draft 1 %, twist 0.1°,
// entry/exit 1°), corners 3 cm.
constexpr Tolerance kClean{0.1, 1.0, 0.1, 1.0, 0.03};

void expectSectionsMatch(const SailAnalysis& a, const SailSurface& truth, const Tolerance& tol) {
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    SCOPED_TRACE("section at " + std::to_string(s.fraction));
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, tol.camber_pct);
    EXPECT_NEAR(s.value.draft_pct, k.draft_pct, tol.draft_pct);
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, tol.twist_deg);
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, tol.end_deg);
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, tol.end_deg);
    EXPECT_TRUE(s.converged);
    // Every parameter carries a positive, finite uncertainty.
    EXPECT_GT(s.uncertainty.camber_pct, 0);
    EXPECT_TRUE(std::isfinite(s.uncertainty.entry_deg));
  }
  const Section& low = a.sections.sections.front();
  EXPECT_DOUBLE_EQ(low.value.twist_rel_deg, 0.0);
  for (const Section& s : a.sections.sections)
    EXPECT_NEAR(s.value.twist_rel_deg, s.value.twist_deg - low.value.twist_deg, 1e-12);
}

TEST(Pipeline, CleanMainsailRecoversKnownSectionsAndCorners) {
  const SailDesign design = exampleDesign(SailType::Main);
  ScanSimulation sim;
  sim.points = 40000;
  const Cloud cloud = sampleSail(design, sim);
  const SailAnalysis a = analyzeSail(cloud);
  const SailSurface truth(design);
  expectSectionsMatch(a, truth, kClean);
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
  EXPECT_FALSE(a.outline.has_peak);
}

TEST(Pipeline, EmptyCloudIsRejected) {
  EXPECT_THROW(analyzeSail(Cloud{}), InvalidInput);
}

TEST(Pipeline, NonFiniteCoordinateIsRejected) {
  Cloud c;
  c.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, std::nan(""), 0)};
  try {
    analyzeSail(c);
    FAIL() << "no exception";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("point 2"), std::string::npos);
  }
}

TEST(Pipeline, PlanarWallIsNotMistakenForASail) {
  // A flat 4 m x 3 m wall with 4 mm noise: segmentation must refuse it.
  Cloud c;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> N(0, 0.004);
  for (int i = 0; i < 20000; ++i) c.points.emplace_back(4 * U(rng), N(rng), 3 * U(rng));
  EXPECT_THROW(analyzeSail(c), AnalysisError);
}

}  // namespace
}  // namespace sailshape
