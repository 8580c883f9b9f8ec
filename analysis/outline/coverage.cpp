// Where the samples stop, and why (SPEC §3). From one unit the samples of a sail stop
// where the sail ends, but also where the beams meet the cloth at grazing incidence
// (returns fail beyond about 70°, none come back at grazing angles) or run out of
// range. Seen from the cloud's viewpoint, each boundary point of the mesh tells which:
// the incidence of the beam on the surface there, and its range. A corner whose
// neighbouring boundary is mostly where the scan stopped was never reached, and the
// point the edges meet there is not the sail's corner.
#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {
namespace {

enum class Stop { Edge, Grazing, Range };

struct BoundaryStop {
  Stop stop = Stop::Edge;
  double incidence_deg = 0;
  double range_m = 0;
};

// Each loop point's incidence and range from the scanner, and why the samples stop there.
// The surface normal is the mean of the vertex normals over the two loop points each
// side (a boundary vertex's own normal rests on one or two triangles).
std::vector<BoundaryStop> stopsAlongLoop(const BoundaryLoop& loop, const Samples& samples, const Vec3& scanner,
                                         const OutlineParams& p) {
  const size_t n = loop.size();
  std::vector<BoundaryStop> stops(n);
  // The next sample out lies a boundary spacing further; ranges carry up to 0.3 % of
  // systematic error (SPEC §3).
  const double range_margin = 2.0 * loop.spacing + 0.003 * p.scanner_max_range_m;
  for (size_t i = 0; i < n; ++i) {
    Vec3 normal = Vec3::Zero();
    const Vec3 ref = samples.normals[loop.vertex[i]];
    for (int k = -2; k <= 2; ++k) {
      const Vec3& nk = samples.normals[loop.vertex[(i + n + static_cast<size_t>(k + static_cast<int>(n))) % n]];
      normal += nk.dot(ref) < 0 ? Vec3(-nk) : nk;
    }
    const Vec3 ray = loop.points[i] - scanner;
    BoundaryStop& s = stops[i];
    s.range_m = ray.norm();
    const double cosine = std::abs(ray.dot(normal)) / std::max(1e-12, s.range_m * normal.norm());
    s.incidence_deg = std::acos(std::min(1.0, cosine)) * kDegPerRad;
    if (p.scanner_max_range_m > 0 && s.range_m >= p.scanner_max_range_m - range_margin) s.stop = Stop::Range;
    else if (s.incidence_deg >= p.grazing_incidence_deg) s.stop = Stop::Grazing;
  }
  return stops;
}

// The loop indices from corner `from` to corner `to`, the way that passes no other corner.
std::vector<size_t> indicesBetween(const BoundaryLoop& loop, const NamedCorners& c, size_t from, size_t to) {
  const size_t n = loop.size();
  for (size_t dir : {size_t{1}, n - 1}) {
    std::vector<size_t> line{from};
    bool blocked = false;
    for (size_t i = (from + dir) % n;; i = (i + dir) % n) {
      line.push_back(i);
      if (i == to) break;
      if (std::find(c.picked.begin(), c.picked.end(), i) != c.picked.end()) {
        blocked = true;
        break;
      }
    }
    if (!blocked) return line;
  }
  return {};
}

double edgeFraction(const std::vector<BoundaryStop>& stops, const std::vector<size_t>& idx) {
  if (idx.empty()) return 0;
  size_t edge = 0;
  for (size_t i : idx) edge += stops[i].stop == Stop::Edge;
  return static_cast<double>(edge) / static_cast<double>(idx.size());
}

// Whether the samples reach the corner at loop index c: the boundary within `around`
// of it, on each side, is mostly where the sail ends. When not, the reason.
std::optional<std::string> notReached(const BoundaryLoop& loop, const std::vector<BoundaryStop>& stops, size_t c,
                                      double around, const char* name, const OutlineParams& p) {
  const size_t n = loop.size();
  for (size_t dir : {size_t{1}, n - 1}) {
    size_t grazing = 0, range = 0, count = 0;
    double widest_deg = 0, farthest_m = 0;
    for (size_t i = c, walked = 0; walked <= n / 2; i = (i + dir) % n, ++walked) {
      const double arc = std::abs(loop.cum[i] - loop.cum[c]);
      if (std::min(arc, loop.total - arc) > around) break;
      ++count;
      grazing += stops[i].stop == Stop::Grazing;
      range += stops[i].stop == Stop::Range;
      widest_deg = std::max(widest_deg, stops[i].incidence_deg);
      farthest_m = std::max(farthest_m, stops[i].range_m);
    }
    if (2 * (grazing + range) <= count) continue;
    const std::string at = std::string("the ") + name + ": the samples stop ";
    if (range >= grazing)
      return at + formatFixed(farthest_m, 1) + " m from the scanner, at the end of its " +
             formatFixed(p.scanner_max_range_m, 0) + " m range";
    return at + "where the beams meet the cloth at up to " + formatFixed(widest_deg, 0) + "° incidence (beyond " +
           formatFixed(p.grazing_incidence_deg, 0) + "° the cloth returns less and less, and nothing at grazing angles)";
  }
  return std::nullopt;
}

}  // namespace

SailOutline::Coverage scanCoverage(const BoundaryLoop& loop, const NamedCorners& c, const Samples& samples,
                                   const Vec3& scanner, const OutlineParams& p) {
  SailOutline::Coverage cov;
  cov.known = true;
  const std::vector<BoundaryStop> stops = stopsAlongLoop(loop, samples, scanner, p);
  cov.luff = edgeFraction(stops, indicesBetween(loop, c, c.tack, c.head));
  cov.foot = edgeFraction(stops, indicesBetween(loop, c, c.tack, c.clew));
  cov.leech = edgeFraction(stops, indicesBetween(loop, c, c.clew, c.has_peak ? c.peak : c.head));
  if (c.has_peak) cov.top = edgeFraction(stops, indicesBetween(loop, c, c.head, c.peak));
  // A corner's neighbourhood: the stretch of boundary its turn is measured over.
  const double around = std::max(5.0 * loop.spacing, 0.02 * loop.total);
  auto check = [&](size_t corner, const char* name, bool& reached) {
    if (auto why = notReached(loop, stops, corner, around, name, p)) {
      reached = false;
      cov.unreached.push_back(*why);
    }
  };
  check(c.tack, "tack", cov.tack);
  check(c.clew, "clew", cov.clew);
  check(c.head, "head", cov.head);
  if (c.has_peak) check(c.peak, "peak", cov.peak);
  return cov;
}

}  // namespace sailshape::outline_internal
