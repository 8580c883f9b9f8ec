#include "analysis/luff_curve.hpp"

#include <cmath>

#include "analysis/errors.hpp"

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
  for (const Vec3& p : o.luff) {
    const Vec3 d = p - o.tack;
    const double along = d.dot(a) / lc.luff_chord_m * 100.0;
    const double fa = d.dot(across), sw = d.dot(plane_n);
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
  return lc;
}

}  // namespace sailshape
