// The realistic-scan generator itself (tests/support/realistic_*), on known answers:
// its sweep samples a flat wall on the unit's angular grid at the right range, a sail
// beyond the scanner's reach gives no point, the points on a sail lie on the design,
// its truth is SailSurface's, and one seed gives one cloud.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "analysis/core/units.hpp"
#include "tests/support/realistic_judge.hpp"
#include "tests/support/realistic_scene.hpp"
#include "tests/support/realistic_sweep.hpp"

namespace sailshape::realistic {
namespace {

// A unit 1 m above the floor of an empty scene, its β = 0 plane facing +X, sweeping β over ±4° and
// α over 84°..96° (±6° about the horizontal).
Config wallConfig(ScannerModel model) {
  Config c;
  c.seed = 7;
  c.unit.model = model;
  c.sensor.model = model;
  c.unit.position = Vec3(0, 0, 1);
  c.unit.p_m = 0;
  c.unit.beta_start_deg = -4;
  c.unit.sweep_deg = 8;
  c.unit.line_step_deg = 0.25;
  c.unit.alpha_from_deg = 84;
  c.unit.alpha_to_deg = 96;
  c.unit.resolution_deg = 1.0 / 6.0;
  return c;
}

Scene wallScene(double distance_m) {
  Scene s;
  const double x = distance_m, h = 5;
  s.objects.push_back({"wall", Material::Cloth, makeQuad(Vec3(x, -h, 1 - h), Vec3(x, h, 1 - h), Vec3(x, h, 1 + h), Vec3(x, -h, 1 + h))});
  return s;
}

TEST(RealisticSweep, SamplesAWallOnTheAngularGridAtItsRange) {
  const double D = 8.0;
  const Config c = wallConfig(ScannerModel::Lms511);
  const Scan scan = sweepScene(c, wallScene(D), 2);
  // 33 lines (−4°..4° in 0.25°) × 73 beams (84°..96° in 1/6°), every one on the wall head-on.
  EXPECT_EQ(scan.lines, 33u);
  EXPECT_EQ(scan.beams, 33u * 73u);
  ASSERT_EQ(scan.cloud.size(), scan.beams);
  ASSERT_TRUE(scan.cloud.hasScanAngles());
  ASSERT_TRUE(scan.cloud.viewpoint.has_value());
  // Along the line of sight: range × (1 + 0.2 % systematic) ± noise (cloth σ 4.1 mm, 5σ) and the
  // device's millimetre rounding; the plane's x is that range times cos of the beam's angle off +X.
  double sum_x = 0;
  for (size_t i = 0; i < scan.cloud.size(); ++i) {
    const Vec3& p = scan.cloud.points[i];
    const double r = (p - *scan.cloud.viewpoint).norm(), r_true = r / (1 + c.sensor.systematic_fraction);
    const Vec3 d = (p - *scan.cloud.viewpoint) / r;
    EXPECT_NEAR(r_true * d.x(), D, 5 * 0.0041 + 0.0005) << "point " << i;
    sum_x += p.x();
  }
  // The mean carries the systematic error: D · 1.002 within σ/√n.
  EXPECT_NEAR(sum_x / static_cast<double>(scan.cloud.size()), D * 1.002, 0.001);
  // Neighbours along a line sit D · (1/6°) apart in z, lines D · 0.25° apart in y (the wall is head-on,
  // so within a few per cent at these small angles, plus the noise along x, which moves neither).
  std::vector<double> dz, dy;
  for (size_t i = 0; i + 1 < scan.cloud.size(); ++i)
    if (std::abs(scan.cloud.beta_rad[i + 1] - scan.cloud.beta_rad[i]) < 1e-4)
      dz.push_back(std::abs(scan.cloud.points[i + 1].z() - scan.cloud.points[i].z()));
  for (size_t i = 0; i + 73 < scan.cloud.size(); ++i)
    dy.push_back(std::abs(scan.cloud.points[i + 73].y() - scan.cloud.points[i].y()));
  std::nth_element(dz.begin(), dz.begin() + dz.size() / 2, dz.end());
  std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
  EXPECT_NEAR(dz[dz.size() / 2], D * std::tan(kRadPerDeg / 6.0), 0.03 * D * kRadPerDeg / 6.0);
  EXPECT_NEAR(dy[dy.size() / 2], D * std::tan(0.25 * kRadPerDeg), 0.03 * D * 0.25 * kRadPerDeg);
  // Each point's stored angles give it back by SPEC §2 with the unit's pose.
  for (size_t i = 0; i < scan.cloud.size(); i += 97) {
    const double r = (scan.cloud.points[i] - *scan.cloud.viewpoint).norm();
    const double a = scan.cloud.alpha_rad[i], b = scan.cloud.beta_rad[i];
    const Vec3 dir = c.unit.pose().linear() * Vec3(std::cos(a), std::sin(a) * std::cos(b), std::sin(a) * std::sin(b));
    EXPECT_LT((*scan.cloud.viewpoint + r * dir - scan.cloud.points[i]).norm(), 1e-9);
  }
}

TEST(RealisticSweep, AWallBeyondTheScannersReachGivesNoPoint) {
  // LMS111: 20 m reach. A wall at 25 m: every beam on it, none back.
  const Scan far = sweepScene(wallConfig(ScannerModel::Lms111), wallScene(25.0));
  EXPECT_TRUE(far.cloud.empty());
  // An LMS511 (80 m) sees the same wall whole.
  const Scan near = sweepScene(wallConfig(ScannerModel::Lms511), wallScene(25.0));
  EXPECT_EQ(near.cloud.size(), near.beams);
}

TEST(RealisticSweep, ASailBeyondAnLms111sReachGivesNoPoint) {
  Config c = drawConfig(11, SailKind::AsymBow, UnitPlace::SternPulpit);
  c.unit.model = c.sensor.model = ScannerModel::Lms111;
  // Move the unit 25 m aft of its place: the whole sail beyond 20 m.
  c.unit.position.x() -= 25 + c.design.luff_m;
  c.unit.alpha_from_deg = 0;
  c.unit.alpha_to_deg = 120;
  const Scan scan = sweepScene(c, buildScene(c));
  EXPECT_EQ(scan.sail_points(), 0u);
  EXPECT_GT(scan.sail_beams[static_cast<size_t>(ReturnStatus::OutOfRange)], 0u);
}

// The nearest point of the design's surface to p: a grid over (f, u), then halving steps about the best.
double distanceToSurface(const SailSurface& s, const Vec3& p) {
  double best = 1e9, bf = 0, bu = 0;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j <= 30; ++j) {
      const double d = (s.at(i / 60.0, j / 30.0) - p).norm();
      if (d < best) best = d, bf = i / 60.0, bu = j / 30.0;
    }
  for (double h = 1.0 / 60; h > 1e-6; h *= 0.5)
    for (int k = 0; k < 3; ++k)
      for (const auto& [df, du] : {std::pair{h, 0.0}, {-h, 0.0}, {0.0, h}, {0.0, -h}}) {
        const double f = std::clamp(bf + df, 0.0, 1.0), u = std::clamp(bu + du, 0.0, 1.0);
        const double d = (s.at(f, u) - p).norm();
        if (d < best) best = d, bf = f, bu = u;
      }
  // Near the head the chordwise direction shrinks to nothing and the search above stalls along the
  // narrow valley of (f, u); Gauss-Newton steps on the surface's tangent plane follow it.
  for (int it = 0; it < 30; ++it) {
    constexpr double e = 1e-6;
    const Vec3 at = s.at(bf, bu);
    Eigen::Matrix<double, 3, 2> J;
    J.col(0) = (s.at(std::min(bf + e, 1.0), bu) - s.at(std::max(bf - e, 0.0), bu)) /
               (std::min(bf + e, 1.0) - std::max(bf - e, 0.0));
    J.col(1) = (s.at(bf, std::min(bu + e, 1.0)) - s.at(bf, std::max(bu - e, 0.0))) /
               (std::min(bu + e, 1.0) - std::max(bu - e, 0.0));
    const Eigen::Vector2d step = J.colPivHouseholderQr().solve(p - at);
    bool moved = false;
    for (double scale = 1; scale > 1e-4 && !moved; scale *= 0.5) {
      const double f = std::clamp(bf + scale * step.x(), 0.0, 1.0), u = std::clamp(bu + scale * step.y(), 0.0, 1.0);
      const double d = (s.at(f, u) - p).norm();
      if (d < best) best = d, bf = f, bu = u, moved = true;
    }
    if (!moved) break;
  }
  return best;
}

TEST(RealisticSweep, PointsOnTheSailLieOnTheDesign) {
  const uint64_t seed = freshSeed();
  SCOPED_TRACE("seed " + std::to_string(seed) + " (SAILSHAPE_REALISTIC_SEED replays it)");
  Config c = drawConfig(seed, SailKind::Genoa, UnitPlace::DeckLeeward);
  // Without noise, bias and mixed pixels the points are where the beams met the sail's mesh:
  // the 120 × 60 mesh lies within millimetres of the surface it was made from.
  c.sensor.noise_scale = 0;
  c.sensor.systematic_fraction = 0;
  c.sensor.mixed_pixels = false;
  const Scan scan = sweepScene(c, buildScene(c), 2);
  const SailSurface surface(c.design);
  ASSERT_GT(scan.sail_points(), 1000u);
  std::vector<size_t> on_sail;
  for (size_t i = 0; i < scan.cloud.size(); ++i)
    if (scan.object[i] == static_cast<int>(scan.sail_object)) on_sail.push_back(i);
  ASSERT_EQ(on_sail.size(), scan.sail_points());
  // 200 of them spread over the sail: millimetre rounding of the range, and the mesh's chords across the
  // curved cloth (≤ 5 mm on these sizes: a 120 × 60 mesh of a chord of at most 12 m at 15 % camber).
  for (size_t k = 0; k < 200; ++k) {
    const size_t i = on_sail[k * on_sail.size() / 200];
    EXPECT_LT(distanceToSurface(surface, scan.cloud.points[i]), 0.006) << "point " << i;
  }
}

TEST(RealisticTruth, IsTheGeneratorsOwnSurface) {
  const uint64_t seed = freshSeed();
  SCOPED_TRACE("seed " + std::to_string(seed));
  for (SailKind kind : kSailKinds) {
    const Config c = drawConfig(seed, kind, UnitPlace::DeckLeeward);
    const Truth t = truthOf(c.design);
    const SailSurface s(c.design);
    ASSERT_EQ(t.sections.size(), std::size(kSectionFractions));
    for (size_t i = 0; i < t.sections.size(); ++i) {
      const KnownSection k = s.section(kSectionFractions[i]);
      EXPECT_EQ(t.sections[i].camber_pct, k.camber_pct);
      EXPECT_EQ(t.sections[i].draft_pct, k.draft_pct);
      EXPECT_EQ(t.sections[i].twist_deg, k.twist_deg);
      EXPECT_EQ(t.sections[i].entry_deg, k.entry_deg);
      EXPECT_EQ(t.sections[i].exit_deg, k.exit_deg);
      EXPECT_EQ(t.sections[i].luff_point, k.luff_point);
    }
    EXPECT_EQ(t.tack, s.tack());
    EXPECT_EQ(t.head, s.head());
    EXPECT_EQ(t.clew, s.clew());
    // An edge's arc is at least its straight distance and, on these gently curved edges, within 3 % of it.
    EXPECT_GE(t.luff_m, (s.head() - s.tack()).norm() - 1e-9);
    EXPECT_LT(t.luff_m, 1.03 * (s.head() - s.tack()).norm());
    EXPECT_GE(t.foot_m, (s.clew() - s.tack()).norm() - 1e-9);
    // A main's luff is straight: its arc is the design's luff length.
    if (kind == SailKind::PinHeadMain) {
      EXPECT_NEAR(t.luff_m, c.design.luff_m, 1e-6);
    }
  }
}

TEST(RealisticConfig, EachKindIsTheSailItNames) {
  const uint64_t seed = freshSeed();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937_64 rng(seed);
  for (int k = 0; k < 3; ++k) {
    const uint64_t s = rng();
    for (SailKind kind : kSailKinds) {
      SCOPED_TRACE(sailKindName(kind) + " seed " + std::to_string(s));
      const Config full = drawConfig(s, kind, UnitPlace::DeckLeeward);
      const Config model = drawConfig(s, kind, UnitPlace::Tunnel);
      const SailSurface surface(full.design);
      // Luffs 6–35 m full size, a model's 1.8–3 m, drawn before the rig: a main or headsail's is cut to
      // fit its mast or stay, a spinnaker's runs from its tack to the masthead (within a few per cent).
      EXPECT_GE(full.design.luff_m, 5.0);
      EXPECT_LE(full.design.luff_m, 36.0);
      EXPECT_GE(model.design.luff_m, 1.4);
      EXPECT_LE(model.design.luff_m, 3.1);
      // Every unit stands clear of its sail by more than the scanner's least range.
      for (const Config* c : {&full, &model}) {
        double nearest = 1e9;
        const SailSurface s(c->design);
        for (int i = 0; i <= 20; ++i)
          for (int j = 0; j <= 10; ++j) nearest = std::min(nearest, (s.at(i / 20.0, j / 10.0) - c->unit.position).norm());
        EXPECT_GT(nearest, scannerSpec(c->unit.model).min_range_m) << unitPlaceName(c->place);
      }
      EXPECT_TRUE(model.boat.tunnel);
      EXPECT_GT(surface.clew().z(), full.boat.deck_z_m);
      const double side = full.design.leeward_port ? 1 : -1;
      switch (kind) {
        case SailKind::SquareTopMain: EXPECT_EQ(full.design.type, SailType::SquareTopMain); break;
        case SailKind::PinHeadMain: EXPECT_EQ(full.design.type, SailType::Main); break;
        case SailKind::Genoa: EXPECT_LT(surface.clew().x(), 0.0) << "a genoa's clew overlaps the mast"; break;
        case SailKind::Jib: EXPECT_GT(surface.clew().x(), -full.boat.mast_radius_m); break;
        case SailKind::AsymBow: EXPECT_NEAR(full.design.tack.x(), full.boat.bow_x_m, 0.02 * full.boat.mast_height_m); break;
        case SailKind::AsymSprit: EXPECT_GT(full.design.tack.x(), full.boat.bow_x_m + 0.05 * full.boat.mast_height_m); break;
        case SailKind::SymSpinnaker:
          EXPECT_NEAR(full.design.leech_m / full.design.luff_m, 1.0, 0.031);
          EXPECT_LT(side * full.design.tack.y(), 0.0) << "tacked on the pole, to windward";
          EXPECT_NEAR(surface.head().y(), 0.0, 1e-6) << "its head at the masthead";
          break;
        case SailKind::CodeZero:
          for (const ProfileStation& st : full.design.stations) EXPECT_LE(st.camber_pct, 8.0);
          EXPECT_LE(full.design.luff_round_m, 0.006 * full.design.luff_m);
          break;
      }
    }
  }
}

TEST(RealisticConfig, OneSeedGivesOneCloud) {
  const uint64_t seed = freshSeed();
  SCOPED_TRACE("seed " + std::to_string(seed));
  const Config a = drawConfig(seed), b = drawConfig(seed);
  EXPECT_EQ(a.summary(), b.summary());
  const Scene scene = buildScene(a);
  const Scan one = sweepScene(a, scene, 1), two = sweepScene(b, buildScene(b), 2);
  ASSERT_EQ(one.cloud.size(), two.cloud.size());
  EXPECT_TRUE(one.cloud.points == two.cloud.points);
  EXPECT_TRUE(one.cloud.alpha_rad == two.cloud.alpha_rad);
  EXPECT_TRUE(one.cloud.beta_rad == two.cloud.beta_rad);
  // The plain variant keeps the points and nothing else.
  const Cloud xyz = plainXyz(one.cloud);
  EXPECT_TRUE(xyz.points == one.cloud.points);
  EXPECT_FALSE(xyz.hasScanAngles());
  EXPECT_FALSE(xyz.viewpoint.has_value());
  EXPECT_FALSE(xyz.hasIntensity());
}

TEST(RealisticJudge, SortsValuesByErrorAgainstTargetAndSigma) {
  EXPECT_EQ(verdictFor(0.2, 0.01, 0.3), Verdict::Within);
  EXPECT_EQ(verdictFor(0.3, 0.0, 0.3), Verdict::Within);
  EXPECT_EQ(verdictFor(0.5, 0.1, 0.3), Verdict::Honest);   // 0.5 ≤ 3 · 0.1 + 0.3
  EXPECT_EQ(verdictFor(0.61, 0.1, 0.3), Verdict::Wrong);   // beyond 0.6
  EXPECT_EQ(verdictFor(1.0, 0.0, 0.3), Verdict::Wrong);    // no σ claimed: any miss beyond the target
  EXPECT_EQ(verdictFor(NAN, 0.1, 0.3), Verdict::Wrong);    // a NaN reported as a result
  EXPECT_EQ(verdictFor(50, INFINITY, 0.3), Verdict::Honest);
}

TEST(RealisticJudge, ASailOutOfViewIsRefusedWhole) {
  // A scene no sail is in view of: the analysis refuses, every value is "refused".
  Config c = drawConfig(3, SailKind::PinHeadMain, UnitPlace::DeckLeeward);
  c.unit.beta_start_deg += 180;  // the sweep turned away from the sail
  c.unit.alpha_from_deg = 80;
  const ConfigRun run = runConfig(c);
  ASSERT_EQ(run.variants.size(), 2u);
  for (const VariantResult& r : run.variants) {
    EXPECT_TRUE(r.refused) << r.variant;
    EXPECT_EQ(r.count(Verdict::Refused), r.values.size());
    EXPECT_EQ(r.values.size(), 3u * 5u + 3u + 3u);
  }
  EXPECT_TRUE(wrongValues(run).empty());
  EXPECT_NE(runToJson(run).find("\"verdict\": \"refused\""), std::string::npos);
}

}  // namespace
}  // namespace sailshape::realistic
