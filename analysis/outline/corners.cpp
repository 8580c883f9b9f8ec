// The sail's corners on its boundary loop: the 3 (or 4) points where the loop
// turns outwards most sharply, named in the boat frame.
#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {
namespace {

// The shorter way round the loop between points a and b, m.
double arcDistance(const BoundaryLoop& loop, size_t a, size_t b) {
  const double d = std::abs(loop.cum[a] - loop.cum[b]);
  return std::min(d, loop.total - d);
}

// Turning angle at point i over arms of length `arm`, degrees; at a corner it
// approaches the exterior angle. Negative where the loop turns inwards: a sail's
// corners all bulge out, while a notch in a sparse edge (a triangle the long-edge
// limit left out) turns as sharply the other way and is no corner.
double turnAt(const BoundaryLoop& loop, size_t i, double arm) {
  const std::vector<Vec3>& pts = loop.points;
  const Vec3 a = pts[i] - loop.pointAt(loop.cum[i] - arm);
  const Vec3 b = loop.pointAt(loop.cum[i] + arm) - pts[i];
  const double c = a.dot(b) / std::max(1e-12, a.norm() * b.norm());
  const double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
  return loop.outwards(a, b) ? angle : -angle;
}

// The sharpest outward turns, up to 4, each at least min_sep along the loop from
// those picked before it, most turning first.
std::vector<size_t> sharpestTurns(const BoundaryLoop& loop, const std::vector<double>& turn, double min_sep) {
  std::vector<size_t> order(loop.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return turn[a] > turn[b]; });
  std::vector<size_t> picked;
  for (size_t i : order) {
    if (picked.size() == 4 || turn[i] <= 0) break;
    bool far = true;
    for (size_t j : picked) far = far && arcDistance(loop, i, j) >= min_sep;
    if (far) picked.push_back(i);
  }
  return picked;
}

// How many of the picked turns are corners: params.corners, or with 0, 4 when the
// 4th makes a square head (window w), else 3.
size_t cornerCount(const BoundaryLoop& loop, const std::vector<size_t>& picked, const std::vector<double>& turn,
                   double w, const OutlineParams& p) {
  if (p.corners != 0) return static_cast<size_t>(p.corners);
  // A 4th corner (picked 2.5 windows at least from the others) must keep turning
  // sharply at twice the scale: a square head is a real edge, not a kink beside
  // the head of a triangular sail nor a local notch in a noisy edge, which turn
  // far less over twice the window than over it. A sparse square top's peak is
  // rounded off over a few samples and turns less over the window than over twice
  // it: over the window half the limit is enough.
  if (!(picked.size() == 4 && turn[picked[3]] >= 0.5 * p.min_fourth_corner_deg &&
        turnAt(loop, picked[3], 2.0 * w) >= p.min_fourth_corner_deg))
    return 3;
  // A square head's two corners both stand near the top of the sail, not
  // halfway up an edge (a kink from a few mast points at the luff).
  std::vector<double> z;
  for (size_t c : picked) z.push_back(loop.points[c].z());
  std::sort(z.begin(), z.end());
  return z[2] - z[1] < 0.6 * (z[3] - z[0]) ? 3 : 4;
}

// The apex of the corner near point c: the point farthest from the chord across
// the corner (window w each side), on its outer side (a notch beside a rounded
// corner can reach farther inwards).
size_t apex(const BoundaryLoop& loop, size_t c, double w) {
  const std::vector<Vec3>& pts = loop.points;
  const Vec3 a = loop.pointAt(loop.cum[c] - w), b = loop.pointAt(loop.cum[c] + w);
  const Vec3 ab = (b - a).normalized();
  double best = -1;
  size_t best_i = c;
  for (size_t i = 0; i < loop.size(); ++i) {
    if (arcDistance(loop, i, c) > w || !loop.outwards(pts[i] - a, b - pts[i])) continue;
    const Vec3 d = pts[i] - a;
    const double dist = (d - ab * d.dot(ab)).norm();
    if (dist > best) {
      best = dist;
      best_i = i;
    }
  }
  return best_i;
}

// Names the corners in the boat frame: head (and peak) highest, tack forward of clew.
void nameCorners(const BoundaryLoop& loop, NamedCorners& corners) {
  const std::vector<Vec3>& pts = loop.points;
  std::vector<size_t> by_z = corners.picked;
  std::sort(by_z.begin(), by_z.end(), [&](size_t a, size_t b) { return pts[a].z() > pts[b].z(); });
  auto forwardFirst = [&](size_t a, size_t b) {
    return pts[a].x() >= pts[b].x() ? std::make_pair(a, b) : std::make_pair(b, a);
  };
  corners.has_peak = corners.picked.size() == 4;
  if (corners.has_peak) {
    std::tie(corners.head, corners.peak) = forwardFirst(by_z[0], by_z[1]);
    std::tie(corners.tack, corners.clew) = forwardFirst(by_z[2], by_z[3]);
  } else {
    corners.head = by_z[0];
    std::tie(corners.tack, corners.clew) = forwardFirst(by_z[1], by_z[2]);
  }
}

}  // namespace

NamedCorners findCorners(const BoundaryLoop& loop, const OutlineParams& p) {
  const double w = p.corner_window_m > 0 ? p.corner_window_m : 0.01 * loop.total;
  NamedCorners corners;
  corners.turn_deg.resize(loop.size());
  for (size_t i = 0; i < loop.size(); ++i) corners.turn_deg[i] = turnAt(loop, i, w);
  std::vector<size_t>& picked = corners.picked;
  picked = sharpestTurns(loop, corners.turn_deg, std::max(2.5 * w, 0.025 * loop.total));
  if (picked.size() < 3)
    throw AnalysisError("[extractOutline] the boundary (" + formatFixed(loop.total, 2) +
                        " m) has fewer than 3 distinct corners");
  const size_t count = cornerCount(loop, picked, corners.turn_deg, w, p);
  if (picked.size() < count)
    throw AnalysisError("[extractOutline] asked for " + std::to_string(count) + " corners, found " +
                        std::to_string(picked.size()));
  picked.resize(count);
  for (size_t& c : picked) c = apex(loop, c, w);
  nameCorners(loop, corners);
  return corners;
}

std::vector<size_t> indicesBetween(const BoundaryLoop& loop, const NamedCorners& corners, size_t from, size_t to) {
  const size_t n = loop.size();
  for (size_t dir : {size_t{1}, n - 1}) {
    std::vector<size_t> line{from};
    bool blocked = false;
    for (size_t i = (from + dir) % n;; i = (i + dir) % n) {
      line.push_back(i);
      if (i == to) break;
      if (std::find(corners.picked.begin(), corners.picked.end(), i) != corners.picked.end()) {
        blocked = true;
        break;
      }
    }
    if (!blocked) return line;
  }
  return {};
}

std::vector<Vec3> walkBetween(const BoundaryLoop& loop, const NamedCorners& corners, size_t from, size_t to) {
  const std::vector<size_t> idx = indicesBetween(loop, corners, from, to);
  if (idx.empty()) throw AnalysisError("[extractOutline] corners are not in sail order along the boundary");
  std::vector<Vec3> line;
  for (size_t i : idx) line.push_back(loop.points[i]);
  return line;
}

}  // namespace sailshape::outline_internal
