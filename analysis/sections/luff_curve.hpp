#pragma once
// Luff curve measures (SPEC §5): the luff polyline seen in the plane of tack,
// head and clew (LUFA) and in the plane through tack and head perpendicular to
// it (LUSW, the luff's vertical "camber", important for spinnakers).
#include "analysis/outline/sail_outline.hpp"

namespace sailshape {

struct LuffCurve {
  double luff_chord_m = 0;        // straight tack → head distance
  // Largest offset of the luff from the tack–head line in each plane, signed:
  // LUFA positive away from the clew, LUSW positive along (clew−tack)×(head−tack).
  double lufa_sag_m = 0, lufa_sag_pct = 0, lufa_position_pct = 0;
  double lusw_sag_m = 0, lusw_sag_pct = 0, lusw_position_pct = 0;
  // 1σ of each, from the outline's: a sag by the luff's σ across it and the
  // tack-head line's there (the corners' σ across the luff, halved); a position by
  // the spread of the luff's points whose offset lies within that σ of the largest.
  struct Uncertainty {
    double luff_chord_m = 0;
    double lufa_sag_m = 0, lufa_sag_pct = 0, lufa_position_pct = 0;
    double lusw_sag_m = 0, lusw_sag_pct = 0, lusw_position_pct = 0;
  } uncertainty;
};

// Throws InvalidInput when the outline has no luff.
LuffCurve measureLuffCurve(const SailOutline& outline);

}  // namespace sailshape
