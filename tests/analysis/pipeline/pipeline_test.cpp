// The whole analysis on synthetic sails whose section parameters are known by
// construction (analysis/sail_generator), in the tolerances of the core issue.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/sail_generator.hpp"
#include "analysis/pipeline/analysis_json.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/sections/luff_curve.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// Issue 2's targets under 4 mm noise at sections 1/4, 1/2, 3/4: camber 0.3 % of
// chord, draft 2 %, twist 0.3°, entry/exit 2.5°; corners within 3 cm.
void expectNoisyTargets(const SailAnalysis& a, const SailDesign& design) {
  const SailSurface truth(design);
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 0.3) << "section " << s.fraction;
    EXPECT_NEAR(s.value.draft_pct, k.draft_pct, 2.0) << "section " << s.fraction;
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 0.3) << "section " << s.fraction;
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, 2.5) << "section " << s.fraction;
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, 2.5) << "section " << s.fraction;
  }
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), 0.03);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), 0.03);
  EXPECT_LT((a.outline.head - truth.head()).norm(), 0.03);
}

struct Tolerance {
  double camber_pct, draft_pct, twist_deg, end_deg, corner_m;
};
// Clean data: the targets (camber 0.1 % of chord, draft 1 %, twist 0.1°,
// entry/exit 1°), corners 3 cm.
constexpr Tolerance kClean{0.1, 1.0, 0.1, 1.0, 0.03};

// A scan of `points` samples on the sail, with range noise σ = noise_m.
ScanSimulation scan(size_t points, uint64_t seed = 1, double noise_m = 0.0) {
  ScanSimulation sim;
  sim.points = points;
  sim.seed = seed;
  sim.noise_sigma_m = noise_m;
  return sim;
}

void expectSectionMatches(const Section& s, const SailSurface& truth, const Tolerance& tol) {
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

void expectSectionsMatch(const SailAnalysis& a, const SailSurface& truth, const Tolerance& tol) {
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) expectSectionMatches(s, truth, tol);
  const Section& low = a.sections.sections.front();
  EXPECT_DOUBLE_EQ(low.value.twist_rel_deg, 0.0);
  for (const Section& s : a.sections.sections)
    EXPECT_NEAR(s.value.twist_rel_deg, s.value.twist_deg - low.value.twist_deg, 1e-12);
}

TEST(Pipeline, CleanMainsailRecoversKnownSectionsAndCorners) {
  const SailDesign design = exampleDesign(SailType::Main);
  const ScanSimulation sim = scan(40000);
  const Cloud cloud = sampleSail(design, sim);
  const SailAnalysis a = analyzeSail(cloud);
  const SailSurface truth(design);
  expectSectionsMatch(a, truth, kClean);
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
  EXPECT_FALSE(a.outline.has_peak);
}

TEST(Pipeline, CleanSquareTopMainsailFindsFourCornersAndKnownSections) {
  const SailDesign design = exampleDesign(SailType::SquareTopMain);
  const ScanSimulation sim = scan(40000);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  const SailSurface truth(design);
  ASSERT_TRUE(a.outline.has_peak);
  expectSectionsMatch(a, truth, kClean);
  EXPECT_LT((a.outline.peak - truth.peak()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
}

// A square top's top edge is 1.2 m long: at 40,000 points a dozen boundary
// samples stand for it near the peak. Its corner curve once took in the head's
// rounded end and fitted a quadratic to a dozen points, which on these seeds
// followed a chance dip in the samples and put the peak 4.5-5 cm low.
TEST(Pipeline, SquareTopPeakStaysWithinTheTargetWhereItsShortTopEdgeIsThinlySampled) {
  const SailDesign design = exampleDesign(SailType::SquareTopMain);
  const SailSurface truth(design);
  for (const auto& [noise, seed] : {std::pair{0.0, 3}, {kSigma, 6}}) {
    SCOPED_TRACE("noise " + std::to_string(noise) + " seed " + std::to_string(seed));
    const ScanSimulation sim = scan(40000, static_cast<uint64_t>(seed), noise);
    const SailAnalysis a = analyzeSail(sampleSail(design, sim));
    ASSERT_TRUE(a.outline.has_peak);
    EXPECT_LT((a.outline.peak - truth.peak()).norm(), kClean.corner_m);
    EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
    EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m);
    EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
  }
}

// The mean distance between `points` samples spread over the design's surface, m.
double sampleSpacing(const SailDesign& design, size_t points) {
  return std::sqrt(meshArea(generateSailMesh(design)) / static_cast<double>(points));
}

// The example square top at these sizes.
SailDesign squareTop(double luff_m, double leech_m, double foot_m, double head_width_m) {
  SailDesign design = exampleDesign(SailType::SquareTopMain);
  design.luff_m = luff_m;
  design.leech_m = leech_m;
  design.foot_m = foot_m;
  design.head_width_m = head_width_m;
  return design;
}

// Its head and peak within corner_m of the truth on each (noise, seed) run of
// kSquareHeadPoints.
constexpr size_t kSquareHeadPoints = 40000;
void expectSquareHeadCorners(const SailDesign& design, std::initializer_list<std::pair<double, int>> runs,
                             double corner_m = kClean.corner_m) {
  const SailSurface truth(design);
  for (const auto& [noise, seed] : runs) {
    SCOPED_TRACE("noise " + std::to_string(noise) + " seed " + std::to_string(seed));
    const SailAnalysis a =
        analyzeSail(sampleSail(design, scan(kSquareHeadPoints, static_cast<uint64_t>(seed), noise)));
    ASSERT_TRUE(a.outline.has_peak);
    EXPECT_LT((a.outline.peak - truth.peak()).norm(), corner_m);
    EXPECT_LT((a.outline.head - truth.head()).norm(), corner_m);
  }
}

TEST(Pipeline, ASquareHeadUnderAMetreWideKeepsItsFourCorners) {
  // A 0.9 m head on a 12 m luff, 3 % of the 29 m outline. A 4th corner once had to
  // stand 4 corner windows (1 % of the outline each) from the others, and this
  // one, 3.0 windows from the head, made the sail a triangle with its head midway
  // across the top edge. Kinks beside a triangle's head turn under 40° over the
  // window (under 20° over twice it); this peak turns 70°.
  expectSquareHeadCorners(squareTop(12.0, 12.1, 4.0, 0.9), {{0.0, 1}, {kSigma, 2}});
}

// A square top's top edge is a short section with its own camber: 1.35 m of
// chord 13 % deep here, a curve the boundary samples of a few windows cannot
// place. A straight line through its dozen boundary vertices passes several cm off
// the surface at the head and moves its crossing with the leech, the peak, as far.
// Frontier windows an eighth of the edge's reach long (the edge less 3 spacings),
// with their points taken on the surface, follow the camber and meet the luff and
// the leech where the sail's corners are.
TEST(Pipeline, ADeepShortTopEdgeMeetsLuffAndLeechAtTheSquareHeadsCorners) {
  SailDesign design = squareTop(13.0, 13.1, 4.6, 1.35);
  design.stations.back().camber_pct = 13;
  expectSquareHeadCorners(design, {{0.0, 1}, {0.0, 2}, {0.0, 3}, {kSigma, 4}, {kSigma, 5}, {kSigma, 6}});
}

// A wider top edge, 2.16 m and 8 % deep, turns more than 0.08 rad over 5 boundary
// spacings near its ends, more than the frontier's windows follow; so its corners
// would keep the quadratics through the boundary, which the rounded-off ends pull
// in, and the head and peak with them by more than half a sample spacing. Judged
// over the shorter windows the frontier takes on an edge this short, it turns less
// than that, and the corners lie within half a spacing.
TEST(Pipeline, AWideTopEdgeIsJudgedOverTheFrontierWindowsItWouldTake) {
  SailDesign design = squareTop(11.35, 11.4, 5.0, 2.16);
  design.stations.back().camber_pct = 8;
  design.stations.back().draft_pct = 48;
  const double half_spacing = 0.5 * sampleSpacing(design, kSquareHeadPoints);
  expectSquareHeadCorners(design, {{0.0, 1}, {0.0, 3}, {0.0, 6}, {kSigma, 1}, {kSigma, 3}, {kSigma, 6}}, half_spacing);
}

// A clean scan loses no sample. The radius filter drops a gennaker's last samples
// near its narrow head (few neighbours there); readmission brings them back only
// if they lie on the surface of the kept points beyond them, and the head curves
// 2-5 cm off those points' plane: judged on that plane the tip samples would stay
// out and the head would lie centimetres low.
TEST(Pipeline, CleanGennakerKeepsItsTipSamplesAndItsHead) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const ScanSimulation sim = scan(40000, 10);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  EXPECT_EQ(a.sail_points, sim.points);
  EXPECT_LT((a.outline.head - SailSurface(design).head()).norm(), kClean.corner_m);
}

// A gennaker's head is a 34° corner: an error e sideways in each edge moves the
// edges' crossing e / sin 17° = 3.4 e along the bisector. Corner curves fitted
// through the boundary vertices (a centimetre of scatter each) over 5 m of edge
// put these seeds' heads 3.0-5.0 cm off, short of the true head. Moved onto the
// outermost samples beside the edges, each known to a few millimetres, the edges
// place the head within the corner target, clean and with 4 mm noise.
TEST(Pipeline, GennakerHeadIsPlacedByTheOutermostSamplesBesideItsEdges) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  for (const auto& [noise, seed] : {std::pair{0.0, 7}, {0.0, 14}, {0.0, 23}, {kSigma, 18}, {kSigma, 27}}) {
    SCOPED_TRACE("noise " + std::to_string(noise) + " seed " + std::to_string(seed));
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, static_cast<uint64_t>(seed), noise)));
    EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
  }
}

// The mesh's boundary rounds off a wide corner over half a metre and more: at a
// gennaker's clew the foot's boundary vertices lay 2-5 cm inside the foot, and
// the corner curves through them put these seeds' clews 3.3-4.8 cm off. Moved
// onto the outermost samples beside the foot and leech (neither turns over 0.08
// rad in a window there), the clew lies within half the 3.4 cm sample spacing.
TEST(Pipeline, GennakerClewIsPlacedByTheOutermostSamplesBesideItsEdges) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  for (const auto& [noise, seed] : {std::pair{0.0, 2}, {0.0, 90}, {kSigma, 29}, {kSigma, 31}}) {
    SCOPED_TRACE("noise " + std::to_string(noise) + " seed " + std::to_string(seed));
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, static_cast<uint64_t>(seed), noise)));
    EXPECT_LT((a.outline.clew - truth.clew()).norm(), 0.017);
  }
}

// A gennaker's foot leaves the tack at its entry angle and curves away: over
// the 60 boundary spacings (5 m of its 7 m) a corner curve used to reach, a
// quadratic put the tack 2-3 cm off along the luff on these seeds. The tack is
// a wide corner, placed by two edges each known to a few millimetres: within
// half the 3.4 cm sample spacing of a 40,000-point scan of this 46 m² sail.
TEST(Pipeline, GennakerTackHoldsWhereItsFootCurvesAway) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  for (const uint64_t seed : {4, 5, 9}) {
    const ScanSimulation sim = scan(40000, seed);
    const SailAnalysis a = analyzeSail(sampleSail(design, sim));
    EXPECT_LT((a.outline.tack - SailSurface(design).tack()).norm(), 0.017) << "seed " << seed;
  }
}

// Where few samples fall near an edge, its boundary runs inside it: a notch. One
// 36 cm long and 4 cm deep cut into the foot from 0.24 m aft of the tack (every
// sample within 4 cm of the foot there removed) bent the quadratic through the
// foot's boundary vertices and with it the tack, by centimetres. The foot's samples'
// lower envelope is bounded only where there are samples: beside the notch it
// follows those before and after it, and the tack stays within the corner target.
TEST(Pipeline, GennakerTackHoldsBesideANotchInItsFoot) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  std::vector<Vec3> foot;  // the foot from 0.24 to 0.60 m aft of the tack
  double along = 0;
  Vec3 last = truth.at(0, 0);
  for (int i = 1; i <= 2000 && along < 0.60; ++i) {
    const Vec3 p = truth.at(0, i / 2000.0);
    along += (p - last).norm();
    last = p;
    if (along >= 0.24) foot.push_back(p);
  }
  ASSERT_GT(foot.size(), 10u);
  for (const uint64_t seed : {6, 8}) {
    const Cloud full = sampleSail(design, scan(60000, seed));
    Cloud notched;
    size_t removed = 0;
    for (const Vec3& q : full.points) {
      bool in_notch = false;
      for (const Vec3& f : foot) in_notch = in_notch || (q - f).norm() < 0.04;
      if (in_notch)
        ++removed;
      else
        notched.points.push_back(q);
    }
    ASSERT_GT(removed, 10u) << "seed " << seed;
    const SailAnalysis a = analyzeSail(notched);
    EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m) << "seed " << seed;
  }
}

// A sparse gennaker (12,000 samples, boundary vertices 17 cm apart): its 6.6 m
// foot is shorter than the corner curve's first reach, and a quadratic over the
// whole foot passed 16 cm off the surface at the tack, where the foot leaves at its
// entry angle. These seeds' tacks lay 3.8-5.4 cm out along the luff (19 of 20 seeds
// over 3 cm); the curve now shortens to follow the turn.
TEST(Pipeline, ASparseGennakersTackFollowsItsFootsTurn) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  for (const uint64_t seed : {1, 5, 10}) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(12000, seed)));
    EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m) << "seed " << seed;
    EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m) << "seed " << seed;
  }
}

// A sparse gennaker's 35° head: its leech's first frontier window (0.8 m long,
// measured from the corner curve through boundary vertices) can lie centimetres out;
// a cubic following it puts the head as far low. The windows are measured again from
// the frontier curve. (The tip beyond the outermost sample of such a head is several
// cm long, so its corner target is the sparse one.)
TEST(Pipeline, ASparseGennakersHeadComesFromItsFrontierMeasuredTwice) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  for (const uint64_t seed : {9, 10, 11}) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(12000, seed)));
    EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m) << "seed " << seed;
  }
}

// At a wide corner the frontier's first window, the one reaching into the corner,
// was left out: the other edge passes through the corner, and the strip's depth
// was half the sail's width at the window's narrowest, next to nothing. The edge
// was extrapolated over a window and a half, and on these seeds a jib's tack came
// out 3.4 and 6 times its reported σ off. The depth is now taken part by part
// along the window. A reported uncertainty is what a crew reads a corner by: the
// error stays within 3σ of it.
TEST(Pipeline, AWideCornersFrontierReachesIntoTheCorner) {
  const SailDesign design = exampleDesign(SailType::Jib);
  const SailSurface truth(design);
  for (const uint64_t seed : {10, 12}) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, seed)));
    EXPECT_LT((a.outline.tack - truth.tack()).norm(), 3.0 * a.outline.uncertainty.tack_m) << "seed " << seed;
  }
}

// A clew's σ counts how far the frontier fits that fit their points as well as the
// chosen one would put it: the least-squares σ alone assumes the chosen polynomial
// is the edge's shape. Without it these clews lay 2.0 of their σ off (RMS); a σ
// that says what it knows gives about 1, and over 8 corners the RMS spreads by
// about 1/√16 of that, so 1.5 is two spreads above.
TEST(Pipeline, AClewsUncertaintyCoversTheChoiceOfItsEdgesFit) {
  const SailDesign design = exampleDesign(SailType::Jib);
  const SailSurface truth(design);
  double z2 = 0;
  const std::vector<uint64_t> seeds{1, 2, 3, 4, 5, 6, 7, 8};
  for (const uint64_t seed : seeds) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, seed)));
    ASSERT_GT(a.outline.uncertainty.clew_m, 0) << "seed " << seed;
    z2 += std::pow((a.outline.clew - truth.clew()).norm() / a.outline.uncertainty.clew_m, 2);
  }
  EXPECT_LT(std::sqrt(z2 / static_cast<double>(seeds.size())), 1.5);
}

// On this seed the surface has a hole that touches the luff at one vertex; the
// outline walked round it and named its far side the clew, 6.5 m from the real one.
TEST(Pipeline, GennakerOutlineStaysOutOfAHoleThatTouchesItsLuff) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const ScanSimulation sim = scan(40000, 20);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  const SailSurface truth(design);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
}

// A gennaker's head whose last sample stands alone: every sample within 20 cm of
// the head but the nearest is gone. The outlier filters drop that one (too few
// neighbours) and readmission leaves it out (the plane of its neighbours 20-35 cm
// back is one the curving head leaves); the corner still counts it, tested on
// the corner's own surface fitted over far more of the sail. Without it the head
// would stop short of the lone sample by the gap to the next one.
TEST(Pipeline, AHeadReachesItsLoneTipSampleThatCleaningRemoved) {
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  const ScanSimulation sim = scan(40000, 3);
  const Vec3 head = truth.head();
  LoneTip cut = isolateTip(sampleSail(design, sim), head, 0.20);
  ASSERT_LT(cut.tip_distance_m, 0.06) << "the sampling left no sample near the head";
  const Vec3 tip = cut.tip;
  Cloud kept = std::move(cut.rest);
  kept.points.push_back(tip);
  const SailAnalysis a = analyzeSail(kept);
  ASSERT_EQ(a.sail_points + 1, kept.size()) << "the lone tip sample was meant to be left out by cleaning";
  // Along the luff-leech bisector (straight up to within a few degrees) the head
  // lies at or beyond the lone sample.
  const Vec3 up = (head - 0.5 * (truth.luffPoint(0.98) + truth.leechPoint(0.98))).normalized();
  EXPECT_GE((a.outline.head - tip).dot(up), -0.002) << "head " << a.outline.head.transpose() << ", tip " << tip.transpose();
}

TEST(Pipeline, CleanJibRecoversKnownSections) {
  const SailDesign design = exampleDesign(SailType::Jib);
  const ScanSimulation sim = scan(40000);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  expectSectionsMatch(a, SailSurface(design), kClean);
  EXPECT_FALSE(a.outline.has_peak);
}

// The chord's ends lie on the luff and leech, which the boundary samples place
// a recess inside the true edges; an upper section's 0.1° is 1.5 mm across its
// 0.9 m chord. The recess taken from the mean offset of every sample near the
// edge spread by 2 mm and left these seeds' upper twists 0.14-0.17° off; the
// outermost samples of each stretch of edge place it within the target.
TEST(Pipeline, CleanMainAndJibTwistsStayWithinATenthOfADegreeOverSeeds) {
  for (const auto& [type, seed] : {std::pair{SailType::Main, 4}, {SailType::Jib, 3}, {SailType::Jib, 4}}) {
    SCOPED_TRACE("type " + std::to_string(static_cast<int>(type)) + " seed " + std::to_string(seed));
    const SailDesign design = exampleDesign(type);
    const ScanSimulation sim = scan(40000, static_cast<uint64_t>(seed));
    const SailAnalysis a = analyzeSail(sampleSail(design, sim));
    const SailSurface truth(design);
    for (const Section& s : a.sections.sections)
      EXPECT_NEAR(s.value.twist_deg, truth.section(s.fraction).twist_deg, kClean.twist_deg) << "section " << s.fraction;
  }
}

TEST(Pipeline, CleanGennakerRecoversKnownSectionsAndLuffCurve) {
  // 400,000 points on the 44 m² gennaker. At the mainsail test's density
  // (100,000 here) its long curved edges are placed to about ±3 mm, which at the
  // 1.8 m chord of the top section is ±0.1° of twist, the target itself (the
  // analysis reports that uncertainty, and the error lands either side of 0.1°
  // from seed to seed); four times the points resolve the target.
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const ScanSimulation sim = scan(400000);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  const SailSurface truth(design);
  expectSectionsMatch(a, truth, kClean);
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), kClean.corner_m);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), kClean.corner_m);
  // The head, where the curved luff meets the leech at a narrow angle: the edges'
  // crossing is weighed against how far the samples reach (sail_outline.cpp).
  EXPECT_LT((a.outline.head - truth.head()).norm(), kClean.corner_m);
  // The luff curve measured on the design's own luff, corners and clew.
  SailOutline design_outline;
  design_outline.tack = truth.tack();
  design_outline.head = truth.head();
  design_outline.clew = truth.clew();
  for (int i = 0; i <= 400; ++i) design_outline.luff.push_back(truth.luffPoint(i / 400.0));
  const LuffCurve expected = measureLuffCurve(design_outline);
  ASSERT_GT(std::abs(expected.lusw_sag_m), 0.3);  // the design's luff really sags
  // Sags are offsets of the luff from the tack–head line, so they carry the
  // corners' error, up to the 3 cm corner tolerance.
  EXPECT_NEAR(a.luff.lufa_sag_m, expected.lufa_sag_m, 0.03);
  EXPECT_NEAR(a.luff.lusw_sag_m, expected.lusw_sag_m, 0.03);
}

TEST(Pipeline, NoisyMainsailRecoversKnownSectionsWithinTheNoiseTargets) {
  // 4 mm range noise (SPEC §3) on a 10 m mainsail: the noisy targets,
  // camber 0.3 % of chord, draft 2 %, twist 0.3°, entry/exit 2.5°; corners 3 cm.
  const SailDesign design = exampleDesign(SailType::Main);
  const ScanSimulation sim = scan(40000, 1, 0.004);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  const SailSurface truth(design);
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 0.3);
    EXPECT_NEAR(s.value.draft_pct, k.draft_pct, 2.0);
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 0.3);
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, 2.5);
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, 2.5);
    // The reported uncertainty is of the size of the noise's effect, not zero.
    EXPECT_GT(s.uncertainty.twist_deg, 0.02);
    EXPECT_LT(s.uncertainty.twist_deg, 1.0);
  }
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), 0.03);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), 0.03);
  EXPECT_LT((a.outline.head - truth.head()).norm(), 0.03);
}

// z = (value − truth) / σ, RMS over 6 seeds × 3 sections of the example sail of
// `type` at 40,000 points, for each (value, truth, σ) that `pick` gives of a section.
template <typename Pick>
double sectionZRms(SailType type, double noise_m, Pick pick) {
  const SailDesign design = exampleDesign(type);
  const SailSurface truth(design);
  double z2 = 0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, seed, noise_m)));
    EXPECT_EQ(a.sections.sections.size(), 3u) << "seed " << seed;
    for (const Section& s : a.sections.sections)
      for (const auto& [value, known, sigma] : pick(s, truth.section(s.fraction))) {
        EXPECT_GT(sigma, 0) << "seed " << seed << " section " << s.fraction;
        z2 += std::pow((value - known) / sigma, 2);
        ++n;
      }
  }
  return std::sqrt(z2 / std::max(n, 1));
}

using ValueTruthSigma = std::vector<std::tuple<double, double, double>>;

TEST(Pipeline, NoisyEndAnglesCarryAnUncertaintyThatCoversTheirError) {
  // Under 4 mm noise the cut points near a chord's ends follow the smoothed surface,
  // whose error is smooth over the smoothing radius and hides in the end fits'
  // residuals: from those alone the entry and exit σ would be a fraction of the
  // error. For an exact σ, z over 6 seeds × 3 sections × 2 angles is 1 ± 0.12 RMS; a σ that
  // leans to safety stays under 1.5, and one four times the error (z under 0.25)
  // would say nothing.
  const double z_rms = sectionZRms(SailType::Main, 0.004, [](const Section& s, const KnownSection& k) {
    return ValueTruthSigma{{s.value.entry_deg, k.entry_deg, s.uncertainty.entry_deg},
                           {s.value.exit_deg, k.exit_deg, s.uncertainty.exit_deg}};
  });
  EXPECT_LT(z_rms, 1.5);
  EXPECT_GT(z_rms, 0.25);
}

TEST(Pipeline, TwistAndChordUncertaintiesMatchTheirErrors) {
  // A section's ends are known across the luff and leech to how well their curves
  // are placed, and along them to how well the corners are (SPEC §5's arc fractions).
  // The luff and leech σ came from the boundary points' scatter, though the curves
  // rest on the samples' lower envelope, and the corners counted nothing: on clean
  // mains the twist σ was 3-7 times the error (z = error/σ at 0.13 RMS here). For an
  // exact σ, z over 6 seeds × 3 sections is 1 ± 0.17 RMS; under 1.5 leans to safety,
  // under 0.25 says nothing.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  double twist_z2 = 0, chord_z2 = 0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, seed)));
    ASSERT_EQ(a.sections.sections.size(), 3u);
    for (const Section& s : a.sections.sections) {
      const KnownSection k = truth.section(s.fraction);
      ASSERT_GT(s.uncertainty.twist_deg, 0);
      ASSERT_GT(s.uncertainty.chord_m, 0);
      twist_z2 += std::pow((s.value.twist_deg - k.twist_deg) / s.uncertainty.twist_deg, 2);
      chord_z2 += std::pow((s.value.chord_m - k.chord_m) / s.uncertainty.chord_m, 2);
      ++n;
    }
  }
  for (const auto& [name, z2] : {std::pair{"twist", twist_z2}, {"chord", chord_z2}}) {
    SCOPED_TRACE(name);
    EXPECT_LT(std::sqrt(z2 / n), 1.5);
    EXPECT_GT(std::sqrt(z2 / n), 0.25);
  }
}

TEST(Pipeline, TheDraftsUncertaintyCarriesTheCrestFitsBias) {
  // The example gennaker's mean lines change their curvature at the crest, which
  // the cubic fitted over ±15 % of the chord does not follow: its maximum lies
  // 0.4-0.6 % of the chord off on a clean scan, where the fit's own σ said
  // 0.05-0.07 % (z = error/σ at 7.8 RMS here). The fit over the window's middle half
  // lies half as far off, and twice the difference is the σ's bias term. For an
  // exact σ, z over 6 seeds × 3 sections is 1 ± 0.17 RMS; under 1.5 leans to
  // safety, under 0.25 says nothing.
  const double z_rms = sectionZRms(SailType::Gennaker, 0.0, [](const Section& s, const KnownSection& k) {
    return ValueTruthSigma{{s.value.draft_pct, k.draft_pct, s.uncertainty.draft_pct}};
  });
  EXPECT_LT(z_rms, 1.5);
  EXPECT_GT(z_rms, 0.25);
}

TEST(Pipeline, OutlineAndLuffCurveUncertaintiesMatchTheirErrors) {
  // The corners, the edges' lengths, the area and the luff curve's sags each carry
  // a σ from the corners' and edges' own. Over 6 seeds of the example gennaker,
  // clean and under 4 mm of noise, z = error/σ (a corner's distance over its σ)
  // must stay under 2 RMS (an exact σ gives 1; the truth's lengths are the design
  // mesh's polylines, themselves a little short of the surface) and over 0.25.
  const SailDesign design = exampleDesign(SailType::Gennaker);
  const SailSurface truth(design);
  SailOutline true_outline;
  for (int i = 0; i <= 2000; ++i) {
    const double f = i / 2000.0;
    true_outline.luff.push_back(truth.luffPoint(f));
    true_outline.leech.push_back(truth.leechPoint(f));
    true_outline.foot.push_back(truth.at(0.0, f));
  }
  true_outline.tack = truth.tack();
  true_outline.clew = truth.clew();
  true_outline.head = truth.head();
  const LuffCurve true_luff = measureLuffCurve(true_outline);
  const double true_area = meshArea(generateSailMesh(design, 400, 200));
  for (double noise : {0.0, 0.004}) {
    std::map<std::string, std::pair<double, int>> z2;
    auto add = [&](const std::string& name, double error, double sigma) {
      ASSERT_GT(sigma, 0) << name;
      z2[name].first += std::pow(error / sigma, 2);
      ++z2[name].second;
    };
    for (uint64_t seed = 1; seed <= 6; ++seed) {
      const SailAnalysis a = analyzeSail(sampleSail(design, scan(40000, seed, noise)));
      const SailOutline& o = a.outline;
      const SailOutline::Uncertainty& u = o.uncertainty;
      add("corner", (o.tack - truth.tack()).norm(), u.tack_m);
      add("corner", (o.clew - truth.clew()).norm(), u.clew_m);
      add("corner", (o.head - truth.head()).norm(), u.head_m);
      add("length", o.luff_length_m - polylineLength(true_outline.luff), u.luff_length_m);
      add("length", o.leech_length_m - polylineLength(true_outline.leech), u.leech_length_m);
      add("length", o.foot_length_m - polylineLength(true_outline.foot), u.foot_length_m);
      add("area", o.area_m2 - true_area, u.area_m2);
      add("lufa", a.luff.lufa_sag_m - true_luff.lufa_sag_m, a.luff.uncertainty.lufa_sag_m);
      add("lusw", a.luff.lusw_sag_m - true_luff.lusw_sag_m, a.luff.uncertainty.lusw_sag_m);
    }
    for (const auto& [name, sum] : z2) {
      const double z_rms = std::sqrt(sum.first / sum.second);
      EXPECT_LT(z_rms, 2.0) << name << ", noise " << noise;
      EXPECT_GT(z_rms, 0.25) << name << ", noise " << noise;
    }
  }
}

TEST(Pipeline, NoisyJibMeetsTheTargetsWithItsTackOnTheSurface) {
  // A jib's foot leaves the tack at the entry angle and curves away in depth;
  // the edges' crossing alone put the tack 3-4 cm off the sail's surface.
  const SailDesign design = exampleDesign(SailType::Jib);
  const ScanSimulation sim = scan(40000, 2, 0.004);
  const SailAnalysis a = analyzeSail(sampleSail(design, sim));
  expectNoisyTargets(a, design);
}

TEST(Pipeline, DenseNoisyMainsailKeepsItsEndAnglesWithinTheNoiseTargets) {
  // Five times denser than above, every point analysed (working_voxel_sigmas 0): more
  // points must not make it worse. The MLS neighbourhood (a fixed count) then spans a smaller
  // patch, and an edge point's one-sided quadratic tilts with the noise unless edge
  // fits take 2k points, not k: the top section's exit angle is the first to show it.
  const SailDesign design = exampleDesign(SailType::Main);
  const ScanSimulation sim = scan(200000, 3, 0.004);
  AnalysisParams every_point;
  every_point.working_voxel_sigmas = 0;
  const SailAnalysis a = analyzeSail(sampleSail(design, sim), every_point);
  EXPECT_EQ(a.working_voxel_m, 0.0);
  EXPECT_EQ(a.working_points, a.sail_points);
  EXPECT_GE(a.mesh.vertices.size(), a.sail_points * 999 / 1000);
  expectNoisyTargets(a, design);
}

// The working resolution asked for at 5 sensor σ: its voxel is never wider than
// 1/500 of the sail's bounding-box diagonal (pipeline.hpp).
AnalysisParams workingResolution() {
  AnalysisParams p;
  p.working_voxel_sigmas = 5;
  return p;
}
double expectedWorkingVoxel(const Cloud& sail) {
  Eigen::AlignedBox3d box;
  for (const Vec3& x : sail.points) box.extend(x);
  return std::min(5 * 0.004, box.diagonal().norm() / 500);
}

// A dense scan goes on at the working resolution: each point the mean of a column's
// samples, a third as many points or fewer, every scan point on the sail still counted.
void expectWorkingResolution(const SailAnalysis& a, const Cloud& scan) {
  // (The sail's box, and so the voxel, may lose an outlier the scan's box holds.)
  EXPECT_NEAR(a.working_voxel_m, expectedWorkingVoxel(scan), 1e-5);
  EXPECT_GE(a.sail_points, scan.size() * 98 / 100);
  EXPECT_LE(a.sail_points, scan.size());
  EXPECT_LE(a.working_points * 3, a.sail_points);
  EXPECT_LE(a.mesh.vertices.size(), a.working_points);
}

TEST(Pipeline, ADenseNoisyScanIsAnalysedAtTheWorkingResolutionWithinTheNoiseTargets) {
  // 200,000 samples of a 10 m main and of a jib, 4 mm noise, with the default
  // parameters: the stages after segmentation work on one mean per column about 2 cm
  // wide (4-5 samples each), and meet the noise targets here.
  for (SailType type : {SailType::Main, SailType::Jib}) {
    SCOPED_TRACE(type == SailType::Main ? "main" : "jib");
    const SailDesign design = exampleDesign(type);
    const Cloud cloud = sampleSail(design, scan(200000, 4, 0.004));
    const SailAnalysis a = analyzeSail(cloud);
    expectWorkingResolution(a, cloud);
    EXPECT_GT(a.working_voxel_m, 0.015);
    expectNoisyTargets(a, design);
  }
}

TEST(Pipeline, ADenseCleanModelSailIsMergedNoCoarserThanAFiveHundredthOfItsSize) {
  // The example main at 1:5 (2 m luff), 150,000 clean samples 2-3 mm apart: 5σ
  // (2 cm) would be a 1/100 of the sail, so the voxel is a 1/500 of its diagonal,
  // and the clean targets hold.
  const SailDesign design = scaleDesign(exampleDesign(SailType::Main), 0.2);
  const Cloud cloud = sampleSail(design, scan(150000, 5));
  const SailAnalysis a = analyzeSail(cloud, workingResolution());
  expectWorkingResolution(a, cloud);
  EXPECT_LT(a.working_voxel_m, 0.005);
  expectSectionsMatch(a, SailSurface(design), kClean);
}

TEST(Pipeline, ScansUnderThreeSamplesAColumnGoOnAtFullResolution) {
  // 40,000 samples of a 10 m main (18 m²) hold about one per 2 cm column: the mean of
  // one or two samples is no better a point, so every sample goes on. At 110,000 they
  // hold about 2.7, where many columns hold one and a narrow head is thinned unevenly
  // (pipeline.cpp, kMinSamplesPerColumn): every sample goes on too.
  for (size_t points : {40000, 110000}) {
    SCOPED_TRACE(points);
    const Cloud cloud = sampleSail(exampleDesign(SailType::Main), scan(points, 6, 0.004));
    const SailAnalysis a = analyzeSail(cloud);
    EXPECT_EQ(a.working_voxel_m, 0.0);
    EXPECT_EQ(a.working_points, a.sail_points);
    EXPECT_GE(a.sail_points, cloud.size() * 98 / 100);
  }
}

TEST(Pipeline, ASparseNoisyScanKeepsTheCamberOfItsUpperSection) {
  // 5,000 samples under 4 mm noise: about 280 points/m² on the example main. 200
  // neighbours then reach 0.48 m, over half the 0.9 m chord at 3/4 height, and the
  // smoothing flattened that section's crest: camber 0.44 % low on average over the
  // first four seeds (the gennaker's 0.59 %). Averaged over the seeds the noise mostly
  // cancels; what is left is the smoothing's bias, which must stay within the noisy
  // target. One seed's upper camber spreads by 0.2 %, so four seeds' mean is known
  // only to 0.1 %, and a head placed 10-14 cm short on two of them once hid 0.1 % of
  // the bias (the section cut lower, where the sail is fuller); twelve seeds' mean is
  // known to 0.06 %. (Over 40 seeds the gennaker's upper camber reads 0.15 % low.)
  for (SailType type : {SailType::Main, SailType::Gennaker}) {
    const SailDesign design = exampleDesign(type);
    const SailSurface truth(design);
    std::vector<double> sum(3, 0.0);
    constexpr int kSeeds = 12;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const SailAnalysis a = analyzeSail(sampleSail(design, scan(5000, seed, 0.004)));
      ASSERT_EQ(a.sections.sections.size(), 3u) << "seed " << seed;
      for (size_t i = 0; i < 3; ++i) {
        const Section& s = a.sections.sections[i];
        sum[i] += s.value.camber_pct - truth.section(s.fraction).camber_pct;
      }
    }
    for (size_t i = 0; i < 3; ++i)
      EXPECT_NEAR(sum[i] / kSeeds, 0.0, 0.3) << sailTypeName(type) << ", section " << i + 1 << " of 3";
  }
}

TEST(Pipeline, ANotchInASparseLeechIsNotTakenForTheTack) {
  // 5,000 samples, 6 cm apart: on this seed the mesh leaves a 9 cm deep notch in the
  // leech halfway up, which turned the boundary more sharply than the rounded tack
  // and was named the tack (4.4 m off; every twist 145-161° off). Corners turn
  // outwards, the notch inwards. (This seed's notch depends on the sampling; the
  // sheet with a wedge cut in, SailOutline.ANotchCutIntoAnEdgeIsNoCorner, holds the
  // case whatever the generator does.)
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const SailAnalysis a = analyzeSail(sampleSail(design, scan(5000, 4)));
  // Two sample spacings: the sparse tip is rounded off over a few of them.
  EXPECT_LT((a.outline.tack - truth.tack()).norm(), 0.12);
  EXPECT_LT((a.outline.clew - truth.clew()).norm(), 0.12);
  EXPECT_LT((a.outline.head - truth.head()).norm(), 0.12);
  ASSERT_EQ(a.sections.sections.size(), 3u);
  // A twist wrong by a fraction of a degree would still be a right tack: 1° is a
  // 5 cm shift over the upper section's 0.9 m chord.
  for (const Section& s : a.sections.sections) EXPECT_NEAR(s.value.twist_deg, truth.section(s.fraction).twist_deg, 1.0);
}

TEST(Pipeline, ASparseSquareTopKeepsItsRoundedPeak) {
  // 5,000 samples on the square top, 7 cm apart: on this seed the rounded-off peak
  // turns the boundary by 34° over the corner window (44° over twice it), and the
  // sail was taken for a triangle.
  const SailDesign design = exampleDesign(SailType::SquareTopMain);
  const SailSurface truth(design);
  const SailAnalysis a = analyzeSail(sampleSail(design, scan(5000, 7)));
  ASSERT_TRUE(a.outline.has_peak);
  // Within two sample spacings: the sparse tips are rounded off over a few of them.
  EXPECT_LT((a.outline.head - truth.head()).norm(), 0.14);
  EXPECT_LT((a.outline.peak - truth.peak()).norm(), 0.14);
}

TEST(Pipeline, NoCornerLandsFarBeyondTheSamples) {
  // The same square top, its fourth corner refused by a limit no peak meets: the sail
  // is taken for a triangle, and its head is where luff and leech cross. Those two,
  // nearly parallel, crossed 3 m above the sail, and the head was put there. A
  // corner lies at most a few sample spacings beyond the samples.
  const SailDesign design = exampleDesign(SailType::SquareTopMain);
  const Cloud samples = sampleSail(design, scan(5000, 7));
  AnalysisParams params;
  params.outline.min_fourth_corner_deg = 120;
  const SailAnalysis a = analyzeSail(samples, params);
  ASSERT_FALSE(a.outline.has_peak);
  for (const Vec3& c : {a.outline.tack, a.outline.clew, a.outline.head}) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& p : samples.points) nearest = std::min(nearest, (p - c).norm());
    EXPECT_LT(nearest, 0.2) << "corner " << c.transpose();
  }
}

// A sail as a 2D scanner on a turntable samples it, given as XYZ only (no scan
// angles, no viewpoint): vertical planes through the scanner `line_rad` apart in
// azimuth, and on each a sample at every section row `along_m` of luff height apart.
Cloud sampleOnScanLines(const SailSurface& surface, const Vec3& scanner, double line_rad, double along_m) {
  auto azimuth = [&](const Vec3& p) { return std::atan2(p.y() - scanner.y(), p.x() - scanner.x()); };
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double a = azimuth(surface.at(i / 20.0, j / 20.0));
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    }
  const int rows = static_cast<int>((surface.head() - surface.tack()).norm() / along_m) + 1;
  Cloud cloud;
  for (double b = std::ceil(lo / line_rad) * line_rad; b <= hi; b += line_rad)
    for (int i = 0; i <= rows; ++i) {
      const double f = static_cast<double>(i) / rows;
      double u0 = 0, u1 = 1, a0 = azimuth(surface.at(f, u0)) - b;
      if (a0 * (azimuth(surface.at(f, u1)) - b) > 0) continue;  // this line misses the row
      for (int k = 0; k < 40; ++k) {
        const double um = 0.5 * (u0 + u1), am = azimuth(surface.at(f, um)) - b;
        if ((am > 0) == (a0 > 0)) {
          u0 = um;
          a0 = am;
        } else {
          u1 = um;
        }
      }
      cloud.points.push_back(surface.at(f, 0.5 * (u0 + u1)));
    }
  return cloud;
}

bool warnsOfScanLinesBeside(const SailAnalysis& a, const std::string& edge) {
  for (const std::string& w : a.warnings)
    if (w.find("outline: " + edge + ": its samples lie on scan lines") != std::string::npos) return true;
  return false;
}

// Scan lines 5 cm apart on the sail run almost along its luff and cross it only
// where the rake carries it over a line: the samples beside the luff form a
// staircase up to a line spacing inside it, and the luff is placed by the last
// line, up to a spacing inside. Where the edge lies between the lines is not in the samples: uniform over a
// spacing, σ = spacing / √12. The analysis says so, and its uncertainties cover it.
TEST(Pipeline, ALuffBesideScanLinesIsSaidSoAndItsUncertaintyCoversALineSpacing) {
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const Vec3 scanner(-2.5, -8.0, 5.0);
  constexpr double kLineSpacing = 0.05;  // m, at the 8.5 m to the sail's middle
  const SailAnalysis a = analyzeSail(sampleOnScanLines(truth, scanner, kLineSpacing / 8.5, 0.02));
  EXPECT_TRUE(warnsOfScanLinesBeside(a, "luff"));
  EXPECT_GE(a.outline.luff_sigma_m, 0.5 * kLineSpacing / std::sqrt(12.0));
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    EXPECT_LT(std::abs(s.value.twist_deg - k.twist_deg), 3.0 * s.uncertainty.twist_deg) << "section " << s.fraction;
  }
}

// Where the rake carries the luff over a scan line, the line ends on it: the edge
// runs through those ends, outside the staircase the last line leaves between
// them (up to 6 cm inside here). Placed by the outermost samples as a scatter's, the
// luff would lie inside by about half a line spacing; through the ends it does not.
TEST(Pipeline, ALuffCrossingItsScanLinesRunsThroughTheirEnds) {
  for (SailType type : {SailType::Main, SailType::SquareTopMain}) {
    SCOPED_TRACE(sailTypeName(type));
    const SailDesign design = exampleDesign(type);
    const SailSurface truth(design);
    const SailAnalysis a = analyzeSail(sampleOnScanLines(truth, Vec3(-2.5, -8.0, 5.0), 0.06 / 8.5, 0.02));
    ASSERT_TRUE(warnsOfScanLinesBeside(a, "luff"));
    ASSERT_EQ(a.sections.sections.size(), 3u);
    for (const Section& s : a.sections.sections) {
      const KnownSection k = truth.section(s.fraction);
      const Vec3 along_chord = (k.leech_point - k.luff_point).normalized();
      EXPECT_LT(std::abs((s.luff_point - k.luff_point).dot(along_chord)), 0.005) << "section " << s.fraction;
    }
  }
}

TEST(Pipeline, AUniformScatterIsNotTakenForScanLines) {
  const SailDesign design = exampleDesign(SailType::Main);
  for (const auto& [points, noise_m] : {std::pair{40000, 0.0}, {40000, 0.004}, {5000, 0.004}}) {
    SCOPED_TRACE(std::to_string(points) + " points, noise " + std::to_string(noise_m));
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(static_cast<size_t>(points), 3, noise_m)));
    for (const char* edge : {"luff", "leech", "foot"}) EXPECT_FALSE(warnsOfScanLinesBeside(a, edge)) << edge;
  }
}

TEST(Pipeline, ATiltThatLosesTheCurveKeepsTheLastPlaneThatHeldIt) {
  // The design mesh of the example main with every triangle taken out that a plane
  // tilted 0.3-3° about the half-height chord would cut and the start plane does not:
  // the start plane holds its whole curve, every tilted one crosses holes. With no
  // bridging allowed, the normal search's first tilt loses the curve and the section
  // is measured in the start plane, with a warning, not left unmeasured.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  Mesh mesh = generateSailMesh(design, 3600, 80);  // rows 3 mm apart: a tilt moves the cut to others
  const SailOutline outline = extractOutline(mesh);
  SectionParams start;
  start.fractions = {0.5};
  start.plane = "perpendicular";
  const Section s0 = cutSections(mesh, outline, start).sections.at(0);
  SectionParams p;
  p.fractions = {0.5};
  p.max_bridged_gap = 0;
  // Whole, the mesh lets the search tilt the plane by more than the 0.3° left alone.
  const Section whole = cutSections(mesh, outline, p).sections.at(0);
  ASSERT_TRUE(whole.converged);
  ASSERT_GT(std::abs(whole.plane_tilt_deg), 0.5);
  const Vec3 c_hat = (s0.leech_point - s0.luff_point).normalized();
  const Vec3 m0 = s0.plane_normal, e0 = c_hat.cross(m0);
  using Triangle = std::array<uint32_t, 3>;
  auto cuts = [&](const Triangle& t, const Vec3& m) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (uint32_t v : t) {
      const double d = (mesh.vertices[v] - s0.luff_point).dot(m);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    return lo <= 0 && hi >= 0;
  };
  // Tilts 0.02° apart: a plane swings under 2 mm at the chord's far end from one to
  // the next, so every triangle (rows 9 mm apart) some tilt in the range cuts is one
  // a sampled tilt cuts. Triangles no tilt reaches (farther off the start plane than
  // the widest tilt swings at the chord's ends) are kept without the loop.
  const double reach = 1.1 * (s0.leech_point - s0.luff_point).norm() * std::sin(3.0 * kRadPerDeg);
  std::vector<Triangle> kept;
  for (const Triangle& t : mesh.triangles) {
    bool near = false;
    for (uint32_t v : t) near = near || std::abs((mesh.vertices[v] - s0.luff_point).dot(m0)) <= reach;
    bool tilted = false;
    for (int k = 0; k <= 135 && near && !tilted; ++k)
      for (double sign : {-1.0, 1.0}) {
        const double a = sign * (0.3 + 0.02 * k) * kRadPerDeg;
        tilted = tilted || cuts(t, (std::cos(a) * m0 + std::sin(a) * e0).normalized());
      }
    if (cuts(t, m0) || !tilted) kept.push_back(t);
  }
  ASSERT_LT(kept.size(), mesh.triangles.size());
  mesh.triangles = std::move(kept);

  const SectionAnalysis a = cutSections(mesh, outline, p);
  ASSERT_EQ(a.sections.size(), 1u);
  EXPECT_TRUE(a.unmeasured.empty());
  const Section& s = a.sections[0];
  EXPECT_DOUBLE_EQ(s.plane_tilt_deg, 0.0);
  EXPECT_FALSE(s.converged);
  EXPECT_TRUE((s.plane_normal - m0).norm() < 1e-12);
  bool kept_warning = false;
  for (const std::string& w : a.warnings) kept_warning = kept_warning || w.find("; kept at 0.0 deg") != std::string::npos;
  EXPECT_TRUE(kept_warning);
  // The start plane lies within a degree or two of the normal-aligned one: the section
  // still meets the clean camber target.
  EXPECT_NEAR(s.value.camber_pct, truth.section(0.5).camber_pct, 0.1);
}

TEST(Pipeline, SceneWithMastBoomAndDeckIsSegmentedToTheSail) {
  const SailDesign design = exampleDesign(SailType::Main);
  const ScanSimulation sim = scan(40000, 1, 0.004);
  const SceneCloud scene = sampleSailScene(design, sim);
  const SailAnalysis a = analyzeSail(scene.cloud);
  // The picked cluster (before cleaning) holds >= 98 % of the sail's points
  // and <= 1 % foreign ones.
  ASSERT_FALSE(a.stages.empty());
  const StageReport& seg = a.stages.front();
  ASSERT_EQ(seg.name, "segmentation");
  EXPECT_GE(static_cast<double>(seg.points_out), 0.98 * static_cast<double>(sim.points));
  EXPECT_LE(static_cast<double>(seg.points_out), 1.01 * static_cast<double>(sim.points));
  // The mast (70 mm, 2 cm forward of the luff) and the boom (60 mm) are found as spars.
  ASSERT_EQ(a.spars.size(), 2u);
  EXPECT_NEAR(a.spars[0].spar.radius_m, 0.07, kSigma / 2);
  EXPECT_NEAR(a.spars[1].spar.radius_m, 0.06, kSigma / 2);
  // With them known, the luff strip their neighbourhoods reached into comes back, and
  // the sections and corners meet the noisy sail-alone targets (issue 2) beside them.
  expectNoisyTargets(a, design);
}

// The square top in its scene, `points` samples on the sail, seeds 1 to `seeds`, clean
// and with σ noise: both spars found, the sail's cluster clean, corners within two sample
// spacings, and sections no further from the truth than the sail's analysed alone by
// more than half the noise targets (nor from the sail alone's by more than the targets).
void expectSparseSceneReadsAsTheSailAlone(size_t points, uint64_t seeds) {
  const SailDesign design = exampleDesign(SailType::SquareTopMain);
  const SailSurface truth(design);
  const double n = static_cast<double>(points);
  const double corner_m = 2 * sampleSpacing(design, points);
  for (double noise : {0.0, kSigma})
    for (uint64_t seed = 1; seed <= seeds; ++seed) {
      SCOPED_TRACE(std::to_string(points) + " points, seed " + std::to_string(seed) + ", noise " +
                   std::to_string(noise));
      const SceneCloud scene = sampleSailScene(design, scan(points, seed, noise));
      const SailAnalysis a = analyzeSail(scene.cloud);
      // The mast (70 mm, upright) and the boom (60 mm, about level), each from a few
      // hundred points to σ.
      ASSERT_EQ(a.spars.size(), 2u);
      const bool mast_first = std::abs(a.spars[0].spar.axis.z()) > std::abs(a.spars[1].spar.axis.z());
      const Spar& mast = a.spars[mast_first ? 0 : 1].spar;
      const Spar& boom = a.spars[mast_first ? 1 : 0].spar;
      EXPECT_NEAR(mast.radius_m, 0.07, kSigma);
      EXPECT_NEAR(boom.radius_m, 0.06, kSigma);
      EXPECT_GT(std::abs(mast.axis.z()), std::cos(10.0 * kRadPerDeg));
      EXPECT_LT(std::abs(boom.axis.z()), std::sin(10.0 * kRadPerDeg));
      // The sail's cluster: at least 98 % of its points, at most 1 % foreign.
      const StageReport& seg = a.stages.front();
      ASSERT_EQ(seg.name, "segmentation");
      EXPECT_LE(static_cast<double>(seg.points_out), 1.01 * n);
      EXPECT_GE(static_cast<double>(seg.points_out), 0.98 * n);
      // Corners within two sample spacings, as the sail alone (the sparse tips are
      // rounded off over a few of them).
      ASSERT_TRUE(a.outline.has_peak);
      EXPECT_LT((a.outline.tack - truth.tack()).norm(), corner_m);
      EXPECT_LT((a.outline.clew - truth.clew()).norm(), corner_m);
      EXPECT_LT((a.outline.head - truth.head()).norm(), corner_m);
      EXPECT_LT((a.outline.peak - truth.peak()).norm(), corner_m);
      // Its sections lie no further from the truth than the sail's alone do, by more
      // than half the noise targets: a fat cylinder through the mast and the luff
      // beside it once took the luff's points and 0.25 % of the camber. (One sample
      // more or less at a corner 9 cm from the next moves it by centimetres, so the
      // two analyses differ either way; a scene that reads closer to the truth than
      // the sail alone has lost nothing.)
      const SailAnalysis alone = analyzeSail(sampleSail(design, scan(points, seed, noise)));
      ASSERT_EQ(a.sections.sections.size(), alone.sections.sections.size());
      for (size_t i = 0; i < a.sections.sections.size(); ++i) {
        const Section &in_scene = a.sections.sections[i], &by_itself = alone.sections.sections[i];
        ASSERT_DOUBLE_EQ(in_scene.fraction, by_itself.fraction);
        const KnownSection k = truth.section(in_scene.fraction);
        EXPECT_LE(std::abs(in_scene.value.camber_pct - k.camber_pct),
                  std::abs(by_itself.value.camber_pct - k.camber_pct) + 0.15)
            << "section " << i;
        EXPECT_LE(std::abs(in_scene.value.twist_deg - k.twist_deg),
                  std::abs(by_itself.value.twist_deg - k.twist_deg) + 0.15)
            << "section " << i;
        EXPECT_NEAR(in_scene.value.camber_pct, by_itself.value.camber_pct, 0.3) << "section " << i;
        EXPECT_NEAR(in_scene.value.twist_deg, by_itself.value.twist_deg, 0.3) << "section " << i;
      }
    }
}

TEST(Pipeline, ASparseSquareTopInItsSceneFindsItsSparsAndKeepsItsCorners) {
  // 5,000 samples on the square top, 7 cm apart, with its mast, boom and deck at that
  // spacing. A normal there is fitted over neighbours half a metre across, rough on a
  // 7 cm mast: 400 random pairs found 0-3 of the two spars in 12 runs, the sail kept the
  // mast's or boom's points, and 8 runs put a corner 20 cm to 6 m off.
  expectSparseSceneReadsAsTheSailAlone(5000, 6);
}

TEST(Pipeline, AVerySparseSquareTopInItsSceneFindsItsSparsAndKeepsItsCorners) {
  // 3,000 samples, 9 cm apart: the mast's samples round its girth are one every 16°,
  // and it must still be found whole, foot to top, with none of its points left in
  // the sail.
  expectSparseSceneReadsAsTheSailAlone(3000, 18);
}

TEST(Pipeline, AFlatMainsailInItsSceneIsFound) {
  // The example mainsail flattened for a breeze, 4-5 % camber: off its best-fit
  // plane it spreads 3.5 cm, under the 5 mm per metre of its 9.5 m extent that
  // once set a sail apart from a wall, and it was refused as "planar".
  SailDesign design = exampleDesign(SailType::Main);
  design.stations = {{0.0, 4, 45, 6, 2, 2}, {0.5, 5, 45, 10, 2, 2}, {1.0, 4.5, 50, 16, 2, 2}};
  const ScanSimulation sim = scan(40000, 1, 0.004);
  const SceneCloud scene = sampleSailScene(design, sim);
  const SailAnalysis a = analyzeSail(scene.cloud);
  ASSERT_FALSE(a.clusters.empty());
  EXPECT_LT(a.clusters.front().plane_rms_m, 0.005 * a.clusters.front().extent_m);
  const StageReport& seg = a.stages.front();
  EXPECT_GE(static_cast<double>(seg.points_out), 0.98 * static_cast<double>(sim.points));
  EXPECT_LE(static_cast<double>(seg.points_out), 1.01 * static_cast<double>(sim.points));
  expectNoisyTargets(a, design);
}

// A scan with a hole: the samples within `radius` of the surface point at
// section fraction f, chord fraction u removed (a sheet's shadow, a dropout).
Cloud withHole(const Cloud& cloud, const SailSurface& surface, double f, double u, double radius) {
  const Vec3 centre = surface.at(f, u);
  Cloud out;
  for (const Vec3& p : cloud.points)
    if ((p - centre).norm() > radius) out.points.push_back(p);
  return out;
}

TEST(Pipeline, AHoleOverTheCrestIsBridgedAndTheSectionStillMeetsTheTargets) {
  // A hole 26 % of the mid section's chord wide, centred on its crest: the cut
  // breaks in two and the section was refused (gaps over 10 % were an error),
  // failing the whole analysis. The bridge keeps the slopes on either side.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const double chord = truth.section(0.5).chord_m;
  const double draft = truth.section(0.5).draft_pct / 100;
  const Cloud holed = withHole(sampleSail(design, scan(40000)), truth, 0.5, draft, 0.13 * chord);
  const SailAnalysis a = analyzeSail(holed);
  ASSERT_EQ(a.sections.sections.size(), 3u);
  const Section& mid = a.sections.sections[1];
  EXPECT_NEAR(mid.bridged_pct, 26, 3);  // the ball meets the section plane in a 26 % chord
  EXPECT_EQ(a.sections.sections[0].bridged_pct, 0);
  EXPECT_EQ(a.sections.sections[2].bridged_pct, 0);
  bool warned = false;
  for (const std::string& w : a.sections.warnings) warned = warned || w.find("section 0.500: a hole") != std::string::npos;
  EXPECT_TRUE(warned);
  expectSectionsMatch(a, truth, kClean);
  // The crest stands inside the bridge: its place is as uncertain as the bridge is wide.
  EXPECT_GT(mid.uncertainty.draft_pct, 26 / std::sqrt(12.0) - 1);
}

TEST(Pipeline, ABridgeOfAWholeChordIsRefused) {
  AnalysisParams p;
  for (double bad : {-0.1, 1.0}) {
    p.sections.max_bridged_gap = bad;
    expectThrowWith<InvalidInput>([&] { analyzeSail(sampleSail(exampleDesign(SailType::Main), scan(40000)), p); },
                                  {"[cutSections]", "max_bridged_gap must be in [0, 1)"});
  }
}

TEST(Pipeline, AHoleWiderThanTheBridgeLeavesItsSectionUnmeasuredAndTheOthersStand) {
  // A hole 44 % of the mid section's chord wide: that section cannot be measured,
  // but it no longer takes the whole analysis with it.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const double chord = truth.section(0.5).chord_m;
  const Cloud holed = withHole(sampleSail(design, scan(40000)), truth, 0.5, 0.45, 0.22 * chord);
  const SailAnalysis a = analyzeSail(holed);
  ASSERT_EQ(a.sections.unmeasured.size(), 1u);
  EXPECT_DOUBLE_EQ(a.sections.unmeasured[0].fraction, 0.5);
  const std::string& why = a.sections.unmeasured[0].reason;
  EXPECT_NE(why.find("fraction 0.500 crosses a hole"), std::string::npos) << why;
  EXPECT_NE(why.find("bridged up to 35 %"), std::string::npos) << why;
  bool warned = false;
  for (const std::string& w : a.sections.warnings) warned = warned || w.find("section 0.500 not measured") != std::string::npos;
  EXPECT_TRUE(warned);
  // The sections either side meet the clean targets, and twist_rel still starts at the lowest.
  ASSERT_EQ(a.sections.sections.size(), 2u);
  EXPECT_DOUBLE_EQ(a.sections.sections[0].fraction, 0.25);
  EXPECT_DOUBLE_EQ(a.sections.sections[1].fraction, 0.75);
  for (const Section& s : a.sections.sections) expectSectionMatches(s, truth, kClean);
  EXPECT_DOUBLE_EQ(a.sections.sections[0].value.twist_rel_deg, 0.0);
  // The JSON says which section is missing and why.
  const nlohmann::json j = analysisToJson(a);
  ASSERT_EQ(j["unmeasured_sections"].size(), 1u);
  EXPECT_DOUBLE_EQ(j["unmeasured_sections"][0]["fraction"].get<double>(), 0.5);
  EXPECT_EQ(j["unmeasured_sections"][0]["reason"].get<std::string>(), why);
  EXPECT_EQ(j["sections"].size(), 2u);
}

TEST(Pipeline, ASparseSectionReadsItsEndAnglesOverAWiderWindow) {
  // 12,000 samples over the 20 m² example main (about 4 cm apart): the upper section's
  // 0.9 m chord holds only a few cut points within 10 % of either end, and its entry and
  // exit were null. Read over up to 20 % of the chord, they meet the clean 1° target.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const SailAnalysis a = analyzeSail(sampleSail(design, scan(12000, 1)));
  bool widened = false;
  for (const std::string& w : a.sections.warnings)
    widened = widened || (w.find("section 0.750: the entry angle is read from") != std::string::npos &&
                          w.find("% of the chord (too few within 10 %)") != std::string::npos);
  EXPECT_TRUE(widened);
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    const KnownSection k = truth.section(s.fraction);
    SCOPED_TRACE("section at " + std::to_string(s.fraction));
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, kClean.end_deg);
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, kClean.end_deg);
    EXPECT_TRUE(std::isfinite(s.uncertainty.entry_deg) && std::isfinite(s.uncertainty.exit_deg));
  }
}

TEST(Pipeline, AnEndAngleWithTooFewPointsIsNamedAsNotMeasuredNotReportedAsNaN) {
  // 2,500 samples over the 20 m² example main (about 9 cm apart): the upper section's 0.9 m chord
  // holds fewer than six cut points within 20 % of an end.
  const SailDesign design = exampleDesign(SailType::Main);
  const SailAnalysis a = analyzeSail(sampleSail(design, scan(2500, 1)));
  size_t named = 0;
  for (const Section& s : a.sections.sections) {
    SCOPED_TRACE("section at " + std::to_string(s.fraction));
    const std::pair<const char*, double> values[] = {
        {"chord_m", s.value.chord_m},     {"camber_pct", s.value.camber_pct}, {"draft_pct", s.value.draft_pct},
        {"twist_deg", s.value.twist_deg}, {"entry_deg", s.value.entry_deg},   {"exit_deg", s.value.exit_deg}};
    // A value is NaN exactly when the section names it as not measured, with why.
    for (const auto& [name, value] : values) {
      const auto why = s.not_measured.find(name);
      EXPECT_EQ(std::isnan(value), why != s.not_measured.end()) << name;
      if (why != s.not_measured.end()) {
        EXPECT_NE(why->second.find("too few points for the"), std::string::npos) << why->second;
        ++named;
      }
    }
  }
  EXPECT_GE(named, 1u) << "this sparse a scan leaves an upper end angle unmeasured";
}

// The cut points lie on the mesh's flat facets, whose slopes step from one to the
// next on a curved section. Read from six points, the upper section's end angles
// of 12,000-point mains spread by 0.5°: 12 of 100 seeds had one over the clean 1°
// target, these by 1.3-2.9°. Read from ten (the window widening to at most 20 % of
// the chord for them), they spread by 0.25-0.3° and 2 of 200 angles exceed 1°.
TEST(Pipeline, SparseUpperSectionsReadTheirEndAnglesFromTenPoints) {
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  for (const uint64_t seed : {16, 28, 54, 58, 63}) {
    const SailAnalysis a = analyzeSail(sampleSail(design, scan(12000, seed)));
    for (const Section& s : a.sections.sections) {
      const KnownSection k = truth.section(s.fraction);
      SCOPED_TRACE("seed " + std::to_string(seed) + " section at " + std::to_string(s.fraction));
      EXPECT_NEAR(s.value.entry_deg, k.entry_deg, kClean.end_deg);
      EXPECT_NEAR(s.value.exit_deg, k.exit_deg, kClean.end_deg);
    }
  }
}

TEST(Pipeline, WhenNoSectionCanBeMeasuredTheAnalysisIsOneErrorNamingIt) {
  const SailDesign design = exampleDesign(SailType::Main);
  const SailSurface truth(design);
  const double chord = truth.section(0.5).chord_m;
  const Cloud holed = withHole(sampleSail(design, scan(40000)), truth, 0.5, 0.45, 0.22 * chord);
  AnalysisParams p;
  p.sections.fractions = {0.5};
  expectThrowWith<AnalysisError>([&] { analyzeSail(holed, p); },
                                 {"[cutSections]", "fraction 0.500", "crosses a hole", "bridged up to 35 %"});
  // Two asked, both through the hole: one error naming each.
  p.sections.fractions = {0.49, 0.51};
  expectThrowWith<AnalysisError>([&] { analyzeSail(holed, p); },
                                 {"[cutSections] no section could be measured: ", "fraction 0.490 crosses a hole",
                                  "; the section plane at fraction 0.510 crosses a hole"});
}

TEST(Pipeline, ABadSectionParameterIsReportedBeforeAnyWork) {
  // A flat wall is refused by sail picking; a bad section parameter must be named
  // first, not after a whole analysis has run.
  Cloud wall;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) wall.points.emplace_back(0.05 * i, 0.0, 0.05 * j);
  AnalysisParams p;
  p.sections.curve_points = 1;
  expectThrowWith<InvalidInput>([&] { analyzeSail(wall, p); }, {"[cutSections]", "curve_points must be >= 2"});
  p.sections.curve_points = 61;
  p.sections.max_tilt_deg = 90;
  expectThrowWith<InvalidInput>([&] { analyzeSail(wall, p); }, {"[cutSections]", "max_tilt_deg must be in (0, 90)"});
  // A working resolution below zero is a mistake, not "off".
  p.sections.max_tilt_deg = 45;
  p.working_voxel_sigmas = -5;
  expectThrowWith<InvalidInput>([&] { analyzeSail(wall, p); },
                                {"[analyzeSail]", "working_voxel_sigmas must be >= 0", "-5"});
  p.working_voxel_sigmas = 5;
  p.working_voxel_of_extent = 0;
  expectThrowWith<InvalidInput>([&] { analyzeSail(wall, p); }, {"[analyzeSail]", "working_voxel_of_extent must be > 0"});
  p.working_voxel_of_extent = 1.0 / 500;
  p.working_column_depth_sigmas = -1;
  expectThrowWith<InvalidInput>([&] { analyzeSail(wall, p); },
                                {"[analyzeSail]", "working_column_depth_sigmas must be >= 0", "-1"});
}

TEST(Pipeline, ACleanWindTunnelModelKeepsItsTopSectionWithinTheCleanTargets) {
  // The example mainsail at 1:5 (2 m luff), 20,000 clean samples: sized by density
  // alone the smoothing's k would pass 500, a neighbourhood wider than half the top
  // section's chord, and bend its entry and exit. Measured clean, k stays small.
  const SailDesign design = scaleDesign(exampleDesign(SailType::Main), 0.2);
  const SailAnalysis a = analyzeSail(sampleSail(design, scan(20000)));
  EXPECT_EQ(a.smoothing_stats.k_used, 40u);
  const SailSurface truth(design);
  expectSectionsMatch(a, truth, kClean);
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

// A real main's scan scaled by 1e30, or written in millimetres, is refused before any
// stage runs: analysed, it gave a 62-digit area and NaN angles.
TEST(Pipeline, ACloudBeyondAnyScannersReachIsRefusedAndMillimetresAreNamed) {
  ScanSimulation sim;
  sim.points = 2000;
  Cloud c = sampleSail(exampleDesign(SailType::Main), sim);
  for (Vec3& p : c.points) p *= 1000.0;
  expectThrowWith<InvalidInput>([&] { analyzeSail(c); }, {"[analyzeSail] the cloud looks like millimetres"});
  for (Vec3& p : c.points) p *= 1e27;
  expectThrowWith<InvalidInput>([&] { analyzeSail(c); }, {"e+31 m from the origin"});
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
