// Whether the corners and edges found make a sail at all (SPEC §2 names them in the
// boat frame: the head highest, the tack forward and low, the luff the edge from the
// tack up to the head). Corners are named by those rules on the sampled boundary and
// then placed where the fitted edges meet; a placement that breaks the rules, or edges
// that cannot close round one sail, come from a boundary that is not the sail's edge
// (a scan cut short, a cluster that is not the sail), and their lengths, and the
// sections placed along them, would be wrong with a small ±.
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {
namespace {

std::string metres(double v) { return formatFixed(v, 2) + " m"; }

[[noreturn]] void contradiction(const std::string& what) {
  throw AnalysisError("[extractOutline] the outline found is not a sail's: " + what +
                      " (the scan may not reach the sail's edges, or the cluster is not the sail)");
}

}  // namespace

void refuseContradictoryOutline(const SailOutline& o) {
  // The head (and a square top's peak) is the highest corner.
  const double foot_top = std::max(o.tack.z(), o.clew.z());
  if (o.head.z() <= foot_top)
    contradiction("the head, placed at a height of " + metres(o.head.z()) + ", is not above the tack (" +
                  metres(o.tack.z()) + ") and the clew (" + metres(o.clew.z()) + ")");
  if (o.has_peak && o.peak.z() <= foot_top)
    contradiction("the peak, placed at a height of " + metres(o.peak.z()) + ", is not above the tack and the clew");
  // The tack is forward of the clew (+X forward).
  if (o.tack.x() <= o.clew.x())
    contradiction("the tack, placed at x " + metres(o.tack.x()) + ", is not forward of the clew (x " +
                  metres(o.clew.x()) + ")");
  // The edges run round one sail: none is longer than the others together (their
  // straight lines cannot break that; an edge that does wanders off the sail).
  const double lengths[4] = {o.luff_length_m, o.leech_length_m, o.foot_length_m, o.has_peak ? o.top_length_m : 0.0};
  const char* names[4] = {"luff", "leech", "foot", "top edge"};
  const double total = lengths[0] + lengths[1] + lengths[2] + lengths[3];
  for (int i = 0; i < 4; ++i)
    if (lengths[i] >= total - lengths[i] && lengths[i] > 0)
      contradiction(std::string("its ") + names[i] + " (" + metres(lengths[i]) +
                    ") is as long as the other edges together (" + metres(total - lengths[i]) + ")");
  // Each edge is a gently curved line between its corners: the most curved on any sail
  // this product measures, a symmetric spinnaker's luff or leech, sags about a quarter
  // of its chord and is some 15 % longer than it. One at least twice its corners' span
  // runs round something else (a clew placed beside the tack, a head beside the clew).
  const Vec3 top_end = o.has_peak ? o.peak : o.head;
  const double chords[4] = {(o.head - o.tack).norm(), (top_end - o.clew).norm(), (o.clew - o.tack).norm(),
                            o.has_peak ? (o.peak - o.head).norm() : 0.0};
  for (int i = 0; i < 4; ++i)
    if (lengths[i] > 0 && 2.0 * chords[i] < lengths[i])
      contradiction(std::string("its ") + names[i] + " runs " + metres(lengths[i]) + " between corners " +
                    metres(chords[i]) + " apart");
  // The luff runs from the tack up to the head: the sail's height, never shorter than
  // its foot on any sail this product measures (mains, headsails, spinnakers, code zeros).
  const double luff_chord = chords[0], foot_chord = chords[2];
  if (luff_chord < foot_chord)
    contradiction("the head lies " + metres(luff_chord) + " from the tack, nearer than the clew (" +
                  metres(foot_chord) + ")");
}

}  // namespace sailshape::outline_internal
