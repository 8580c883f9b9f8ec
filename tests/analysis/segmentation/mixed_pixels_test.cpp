// Mixed pixels on a scan's own grid (analysis/mixed_pixels): scans built sample by
// sample on a turntable grid (SPEC §2: a line per β, a sample per α) with known
// surfaces and known mixed samples between them, and 4 mm range noise (SPEC §3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <set>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/pipeline/pipeline.hpp"
#include "analysis/segmentation/mixed_pixels.hpp"

using namespace sailshape;

namespace {

constexpr double kSigma = 0.004;                  // SPEC §3, sail cloth
constexpr double kAlphaStep = M_PI / 180.0 / 6;   // LMS511 at 1/6°
constexpr double kBetaStep = 2 * kAlphaStep;      // the turntable's step between lines
const Vec3 kScanner(0.5, -0.2, 1.0);

// The beam's direction for mirror angle α and turntable angle β (SPEC §2, p = 0).
Vec3 direction(double alpha, double beta) {
  return Vec3(std::cos(alpha), std::sin(alpha) * std::cos(beta), std::sin(alpha) * std::sin(beta));
}

struct Sample {
  double range = 0;
  bool mixed = false;  // a range between two surfaces, by construction
};
// The true range of the sample at grid place (line l, step k), if any.
using Truth = std::function<std::optional<Sample>(int l, int k)>;

constexpr double kAlpha0 = 80 * kRadPerDeg, kBeta0 = -0.3;
constexpr int kLines = 120, kSteps = 240;

Cloud scan(const Truth& truth, unsigned seed, std::vector<char>* mixed = nullptr) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, kSigma);
  Cloud c;
  c.viewpoint = kScanner;
  for (int l = 0; l < kLines; ++l)
    for (int k = 0; k < kSteps; ++k) {
      const std::optional<Sample> s = truth(l, k);
      if (!s) continue;
      const double alpha = kAlpha0 + k * kAlphaStep;
      // The turntable turns on while the mirror sweeps: β drifts along the line.
      const double beta = kBeta0 + l * kBetaStep + 0.4 * kBetaStep * k / kSteps;
      c.points.push_back(kScanner + (s->range + noise(rng)) * direction(alpha, beta));
      c.alpha_rad.push_back(alpha);
      c.beta_rad.push_back(beta);
      if (mixed) mixed->push_back(s->mixed);
    }
  return c;
}

// Range to the plane through `q` with normal `n` along the ray of (l, k).
double rangeToPlane(int l, int k, const Vec3& q, const Vec3& n) {
  const double alpha = kAlpha0 + k * kAlphaStep, beta = kBeta0 + l * kBetaStep + 0.4 * kBetaStep * k / kSteps;
  const Vec3 d = direction(alpha, beta);
  return (q - kScanner).dot(n) / d.dot(n);
}

// A sail-like panel 3.5 m off, square to the scanner's middle beam, over the grid's
// middle (lines 30-89, steps 60-179); behind it, 0.3 m further, a second sail
// (the main's head against the gennaker in the tunnel). Where a beam leaves the
// panel, its footprint straddles both for `transition` samples, whose ranges step
// from the panel's towards the one behind in equal parts.
Truth panelBeforeSail(int transition) {
  const Vec3 mid = direction(kAlpha0 + 120 * kAlphaStep, kBeta0 + 60 * kBetaStep);
  const Vec3 front = kScanner + 3.5 * mid, back = kScanner + 3.8 * mid;
  return [=](int l, int k) -> std::optional<Sample> {
    const double rf = rangeToPlane(l, k, front, -mid), rb = rangeToPlane(l, k, back, -mid);
    const bool inside = l >= 30 && l < 90 && k >= 60 && k < 180;
    if (inside) return Sample{rf, false};
    // Samples past the panel's edge, by how many (along the line or across the lines).
    const int past_k = k < 60 ? 60 - k : k >= 180 ? k - 179 : 0;
    const int past_l = l < 30 ? 30 - l : l >= 90 ? l - 89 : 0;
    const bool beside = (past_k == 0 && past_l > 0) || (past_l == 0 && past_k > 0);
    const int past = std::max(past_k, past_l);
    if (beside && past <= transition) {
      const double w = static_cast<double>(past) / (transition + 1);
      return Sample{(1 - w) * rf + w * rb, true};
    }
    return Sample{rb, false};
  };
}

std::set<uint32_t> removedOf(const Cleaning& c) { return {c.removed.begin(), c.removed.end()}; }

}  // namespace

TEST(MixedPixels, TheFringeBetweenASailAndTheSailBehindItGoesAndNothingElse) {
  for (int transition : {1, 2, 3}) {
    std::vector<char> mixed;
    const Cloud c = scan(panelBeforeSail(transition), 7 + transition, &mixed);
    const Cleaning r = removeMixedPixels(c);
    ASSERT_EQ(r.kept.size() + r.removed.size(), c.size());
    EXPECT_TRUE(r.warnings.empty());
    size_t mixed_total = 0, mixed_removed = 0, pure_removed = 0;
    const std::set<uint32_t> gone = removedOf(r);
    for (uint32_t i = 0; i < c.size(); ++i) {
      mixed_total += mixed[i];
      if (gone.count(i)) (mixed[i] ? mixed_removed : pure_removed) += 1;
    }
    ASSERT_EQ(mixed_total, 2u * (60 + 120) * transition) << "the panel's rim, transition deep";
    // Each step of the transition is 0.3 m / (transition + 1), against the 4.9 cm
    // (5 σ of a second difference, √6 · 4 mm = 9.8 mm) that makes an edge: at 15
    // and 10 cm an edge is missed once in 10⁸ or more; at 7.5 cm, 2.65 of those σ
    // above it, once in 250, and a mixed sample needs both its edges: ≤ 1 % stay
    // on average, 2 % allowed.
    if (transition < 3)
      EXPECT_EQ(mixed_removed, mixed_total) << "transition " << transition;
    else
      EXPECT_GE(mixed_removed, 0.98 * static_cast<double>(mixed_total)) << "transition " << transition;
    // A pure sample goes only on a 5 σ coincidence of noise on both sides of it.
    EXPECT_EQ(pure_removed, 0u) << "transition " << transition;
  }
}

TEST(MixedPixels, ASteepSurfaceIsNotAnEdge) {
  // A plane turned 60° away from the scanner's middle beam and seen up to 79°
  // incidence (beyond, as the sensor, no return): ranges step by up to 5 times the
  // sample spacing, evenly; nothing lies between two surfaces.
  const Vec3 mid = direction(kAlpha0 + 120 * kAlphaStep, kBeta0 + 60 * kBetaStep);
  const Vec3 q = kScanner + 3.0 * mid;
  const Vec3 n = Eigen::AngleAxisd(60 * kRadPerDeg, mid.unitOrthogonal()) * -mid;
  double steepest = 0;
  const Cloud c = scan(
      [&](int l, int k) -> std::optional<Sample> {
        const double alpha = kAlpha0 + k * kAlphaStep, beta = kBeta0 + l * kBetaStep + 0.4 * kBetaStep * k / kSteps;
        const double incidence = std::acos(std::abs(direction(alpha, beta).dot(n))) * kDegPerRad;
        if (incidence > 79) return std::nullopt;
        steepest = std::max(steepest, incidence);
        return Sample{rangeToPlane(l, k, q, n), false};
      },
      3);
  ASSERT_GT(steepest, 78.0) << "the plane must be seen steeply somewhere";
  ASSERT_GT(c.size(), 10000u);
  EXPECT_TRUE(removeMixedPixels(c).removed.empty());
}

TEST(MixedPixels, AThinObjectInFrontAndAGapOntoTheBackgroundStay) {
  // A spar 4 samples wide 0.8 m in front of a wall (nearer than both sides), and a
  // slot 4 samples wide through a panel onto the wall (farther than both sides).
  const Vec3 mid = direction(kAlpha0 + 120 * kAlphaStep, kBeta0 + 60 * kBetaStep);
  const Vec3 wall = kScanner + 4.0 * mid, panel = kScanner + 3.2 * mid;
  const Truth truth = [&](int l, int k) -> std::optional<Sample> {
    const bool spar = k >= 50 && k < 54;
    const bool slot = k >= 150 && k < 154;
    const bool on_panel = k >= 120 && !slot;
    return Sample{rangeToPlane(l, k, (spar || on_panel) ? panel : wall, -mid), false};
  };
  EXPECT_TRUE(removeMixedPixels(scan(truth, 5)).removed.empty());
}

TEST(MixedPixels, AgainstTheSkyTheEdgeSamplesStay) {
  // Nothing behind the panel: beyond its edge no return at all, so no range lies between two surfaces.
  const Truth sail = panelBeforeSail(3);
  const Truth truth = [&](int l, int k) -> std::optional<Sample> {
    if (l < 30 || l >= 90 || k < 60 || k >= 180) return std::nullopt;
    return sail(l, k);
  };
  EXPECT_TRUE(removeMixedPixels(scan(truth, 9)).removed.empty());
}

TEST(MixedPixels, TheCloudsOrderDoesNotMatter) {
  std::vector<char> mixed;
  const Cloud c = scan(panelBeforeSail(2), 21, &mixed);
  std::vector<uint32_t> order(c.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(4));
  const Cloud shuffled = selectPoints(c, order);
  const Cleaning a = removeMixedPixels(c), b = removeMixedPixels(shuffled);
  std::set<uint32_t> b_in_c;
  for (uint32_t j : b.removed) b_in_c.insert(order[j]);
  EXPECT_FALSE(a.removed.empty());
  EXPECT_EQ(removedOf(a), b_in_c);
}

TEST(MixedPixels, WithoutScanAnglesOrViewpointEveryPointStaysAndItSaysWhy) {
  Cloud c = scan(panelBeforeSail(2), 2);
  Cloud no_view = c;
  no_view.viewpoint.reset();
  Cleaning r = removeMixedPixels(no_view);
  EXPECT_EQ(r.kept.size(), c.size());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], "mixed pixels not looked for: the cloud has no viewpoint (scanner position)");
  Cloud no_angles = c;
  no_angles.alpha_rad.clear();
  no_angles.beta_rad.clear();
  r = removeMixedPixels(no_angles);
  EXPECT_EQ(r.kept.size(), c.size());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], "mixed pixels not looked for: the cloud has no scan angles (alpha, beta)");
  // And so does the pipeline's stage: a cloud without them is analysed as before.
  EXPECT_EQ(withoutMixedPixels(no_angles, {}).size(), c.size());
}

TEST(MixedPixels, BadInputIsOneClearError) {
  Cloud c = scan(panelBeforeSail(2), 2);
  Cloud short_alpha = c;
  short_alpha.alpha_rad.pop_back();
  try {
    removeMixedPixels(short_alpha);
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_EQ(std::string(e.what()), "[removeMixedPixels] the cloud has " + std::to_string(c.size()) + " points but " +
                                         std::to_string(c.size() - 1) + " alpha and " + std::to_string(c.size()) +
                                         " beta angles");
  }
  Cloud nan_beta = c;
  nan_beta.beta_rad[5] = std::nan("");
  try {
    removeMixedPixels(nan_beta);
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[removeMixedPixels] point 5 has a non-finite scan angle");
  }
  MixedPixelParams p;
  p.max_incidence_deg = 90;
  EXPECT_THROW(removeMixedPixels(c, p), InvalidInput);
  p = {};
  p.jump_sigmas = 0;
  EXPECT_THROW(removeMixedPixels(c, p), InvalidInput);
  p = {};
  p.max_missing = -1;
  EXPECT_THROW(removeMixedPixels(c, p), InvalidInput);
  AnalysisParams ap;
  ap.mixed.max_run_rad = 0;
  try {
    analyzeSail(c, ap);
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "[removeMixedPixels] max_run_rad must be > 0 (got 0.000000)");
  }
}

// A corner beside a scan line the sweep lost: the samples place it on the last line
// received, and the edge may lie a line spacing further out for each line lost in a
// row beside it; that joins its σ. Lines lost elsewhere change nothing.
TEST(LostScanLines, WidenTheCornersBesideThem) {
  const Vec3 mid = direction(kAlpha0 + 120 * kAlphaStep, kBeta0 + 60 * kBetaStep);
  const Vec3 front = kScanner + 3.5 * mid;
  Cloud c = scan(
      [&](int l, int k) -> std::optional<Sample> {
        if (l < 30 || l >= 90 || k < 60 || k >= 180) return std::nullopt;
        return Sample{rangeToPlane(l, k, front, -mid), false};
      },
      3);
  EXPECT_NEAR(scanLineStepRad(c), kBetaStep, 1e-9);
  // The panel's corners, where its samples end.
  auto at = [&](int l, int k) {
    const double alpha = kAlpha0 + k * kAlphaStep, beta = kBeta0 + l * kBetaStep + 0.4 * kBetaStep * k / kSteps;
    return Vec3(kScanner + rangeToPlane(l, k, front, -mid) * direction(alpha, beta));
  };
  SailOutline o;
  o.tack = at(30, 60);
  o.head = at(30, 179);
  o.clew = at(89, 60);
  o.uncertainty.tack_m = o.uncertainty.head_m = o.uncertainty.clew_m = 0.005;
  // A lost line is stored at its middle beam.
  auto lostLine = [&](int l) { return kBeta0 + l * kBetaStep + 0.2 * kBetaStep; };
  auto spacingAt = [&](const Vec3& p) { return (p - kScanner).norm() * kBetaStep; };
  {
    SailOutline w = o;
    c.lost_beta_rad = {lostLine(50), lostLine(92)};  // inside the panel; two lines past its far edge
    EXPECT_TRUE(widenCornersBesideLostLines(w, c).empty());
    EXPECT_EQ(w.uncertainty.tack_m, 0.005);
    EXPECT_EQ(w.uncertainty.clew_m, 0.005);
  }
  for (const int lost : {1, 2}) {
    SailOutline w = o;
    c.lost_beta_rad.clear();
    for (int l = 30 - lost; l < 30; ++l) c.lost_beta_rad.push_back(lostLine(l));
    const std::vector<std::string> warnings = widenCornersBesideLostLines(w, c);
    ASSERT_EQ(warnings.size(), 2u) << "tack and head";
    EXPECT_EQ(warnings[0].rfind("tack: ", 0), 0u) << warnings[0];
    EXPECT_NEAR(w.uncertainty.tack_m, std::hypot(0.005, lost * spacingAt(o.tack)), 1e-12);
    EXPECT_NEAR(w.uncertainty.head_m, std::hypot(0.005, lost * spacingAt(o.head)), 1e-12);
    EXPECT_EQ(w.uncertainty.clew_m, 0.005);
  }
  // Without a viewpoint nothing says how far apart the lines lie.
  c.viewpoint.reset();
  SailOutline w = o;
  EXPECT_TRUE(widenCornersBesideLostLines(w, c).empty());
  EXPECT_EQ(w.uncertainty.tack_m, 0.005);
}
