// The luff curve measures on a luff of known shape: a parabola bowed away from
// the clew in the plane of tack, head and clew.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/sections/luff_curve.hpp"

namespace sailshape {
namespace {

// A 10 m luff up z from the origin, bowed S at mid-height away from a clew at +x.
SailOutline bowedLuff(double sag_m, double luff_sigma_m) {
  SailOutline o;
  o.tack = Vec3::Zero();
  o.head = Vec3(0, 0, 10);
  o.clew = Vec3(4, 0, 0);
  for (int i = 0; i <= 1000; ++i) {
    const double f = i / 1000.0;
    o.luff.emplace_back(-sag_m * 4 * f * (1 - f), 0, 10 * f);
  }
  o.luff_sigma_m = luff_sigma_m;
  return o;
}

}  // namespace

TEST(LuffCurve, AParabolicLuffHasItsSagAtMidHeightWithinTheSpreadItsSigmaAllows) {
  constexpr double kSag = 0.10, kSigma = 0.002;
  const LuffCurve l = measureLuffCurve(bowedLuff(kSag, kSigma));
  EXPECT_NEAR(l.lufa_sag_m, kSag, 1e-6);
  EXPECT_NEAR(l.lufa_position_pct, 50.0, 0.1);
  EXPECT_NEAR(l.lusw_sag_m, 0.0, 1e-9);
  EXPECT_NEAR(l.uncertainty.lufa_sag_m, kSigma, 1e-12);  // no corner σ: the luff's own
  // Within σ of the largest offset: 4f(1 − f) ≥ 1 − σ/S, a stretch √(σ/S) of the
  // luff long (14.1 %), spread uniformly: 14.1 % / √12.
  EXPECT_NEAR(l.uncertainty.lufa_position_pct, 100.0 * std::sqrt(kSigma / kSag) / std::sqrt(12.0), 0.05);
  // A luff flat out of the plane has its largest LUSW offset anywhere along it.
  EXPECT_GT(l.uncertainty.lusw_position_pct, 25.0);
}

}  // namespace sailshape
