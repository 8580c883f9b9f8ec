#include "analysis/sections/luff_curve.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "analysis/core/errors.hpp"

namespace sailshape {

LuffCurve measureLuffCurve(const SailOutline& o) {
  if (o.luff.size() < 2) throw InvalidInput("[measureLuffCurve] outline has no luff");
  LuffCurve lc;
  const Vec3 axis = o.head - o.tack;
  lc.luff_chord_m = axis.norm();
  if (lc.luff_chord_m <= 0) throw InvalidInput("[measureLuffCurve] tack and head coincide");
  const Vec3 a = axis / lc.luff_chord_m;
  Vec3 plane_n = (o.clew - o.tack).cross(axis);
  if (plane_n.norm() == 0) throw InvalidInput("[measureLuffCurve] tack, head and clew are collinear");
  plane_n.normalize();
  // In-plane direction perpendicular to the luff line, pointing away from the clew.
  Vec3 across = plane_n.cross(a);
  if (across.dot(o.clew - o.tack) > 0) across = -across;
  double best_fa = 0, best_sw = 0;
  std::vector<std::array<double, 3>> profile;  // along (%), in-plane and out-of-plane offsets (m)
  for (const Vec3& p : o.luff) {
    const Vec3 d = p - o.tack;
    const double along = d.dot(a) / lc.luff_chord_m * 100.0;
    const double fa = d.dot(across), sw = d.dot(plane_n);
    profile.push_back({along, fa, sw});
    if (std::abs(fa) > std::abs(best_fa)) {
      best_fa = fa;
      lc.lufa_position_pct = along;
    }
    if (std::abs(sw) > std::abs(best_sw)) {
      best_sw = sw;
      lc.lusw_position_pct = along;
    }
  }
  lc.lufa_sag_m = best_fa;
  lc.lusw_sag_m = best_sw;
  lc.lufa_sag_pct = 100.0 * best_fa / lc.luff_chord_m;
  lc.lusw_sag_pct = 100.0 * best_sw / lc.luff_chord_m;

  LuffCurve::Uncertainty& u = lc.uncertainty;
  u.luff_chord_m = o.uncertainty.luff_length_m;
  const double sag_sigma = std::hypot(o.luff_sigma_m, o.uncertainty.luff_line_m);
  u.lufa_sag_m = u.lusw_sag_m = sag_sigma;
  u.lufa_sag_pct = u.lusw_sag_pct = 100.0 * sag_sigma / lc.luff_chord_m;
  // Where the offset is within its σ of the largest, the largest could lie: its
  // place spreads over that stretch (uniformly: its length / √12).
  auto positionSigma = [&](size_t column, double best) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& q : profile)
      if (std::abs(q[column]) >= std::abs(best) - sag_sigma) {
        lo = std::min(lo, q[0]);
        hi = std::max(hi, q[0]);
      }
    return hi > lo ? (hi - lo) / std::sqrt(12.0) : 0.0;
  };
  u.lufa_position_pct = positionSigma(1, best_fa);
  u.lusw_position_pct = positionSigma(2, best_sw);
  return lc;
}

}  // namespace sailshape
