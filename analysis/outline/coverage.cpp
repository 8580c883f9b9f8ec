// Where the samples stop, and why (SPEC §3). From one unit the samples of a sail stop
// where the sail ends, but also where the beams meet the cloth at grazing incidence
// (returns fail beyond about 70°, none come back at grazing angles), run out of
// range, or meet something in the way first (a mast, a stay: its shadow on the sail).
// Seen from the cloud's viewpoint, each boundary point of the mesh tells which: the
// incidence of the beam on the surface there, its range, and whether the beam just
// beyond it met another sample of the scene nearer the scanner. A corner whose
// neighbouring boundary is mostly where the scan stopped was never reached, and the
// point the edges meet there is not the sail's corner.
#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/outline/outline_internal.hpp"
#include "analysis/spatial/direction_map.hpp"

namespace sailshape::outline_internal {
namespace {

using Stop = SailOutline::Coverage::Stop;
constexpr size_t kStopKinds = 5;

struct BoundaryStop {
  Stop stop = Stop::Edge;
  double incidence_deg = 0;
  double range_m = 0;
  double shadow_range_m = 0;  // how far from the scanner the nearest thing in the way stands (Shadow)
  // Edge beside a narrow shadow: the sail's edge lies between the boundary and this far
  // beyond it, where the beams pass the thing in the way again and meet nothing of the
  // sail (0: no shadow), m.
  double bracket_m = 0;
};

// Each loop point's incidence and range from the scanner, and why the samples stop there.
// The surface normal is the mean of the vertex normals over the two loop points each
// side (a boundary vertex's own normal rests on one or two triangles).
std::vector<BoundaryStop> stopsAlongLoop(const BoundaryLoop& loop, const Samples& samples, const Vec3& scanner,
                                         const std::vector<Vec3>& scene, double around, const OutlineParams& p) {
  const size_t n = loop.size();
  std::vector<BoundaryStop> stops(n);
  // The next sample out lies a boundary spacing further; ranges carry up to 0.3 % of
  // systematic error (SPEC §3).
  const double range_margin = 2.0 * loop.spacing + 0.003 * p.scanner_max_range_m + 2.0 * p.scanner_position_sigma_m;
  // The beams' angular spacing: the boundary's sample spacing over its range, and
  // at least the coarser step of the scan's angular grid (along its lines or between
  // them). The scene's samples stand on that grid, so a beam just beyond the boundary
  // that met something nearer has a scene sample within a cell or two of it; cells
  // narrower than the grid's coarser step leave directions between its samples
  // empty, read as beams that met nothing.
  std::vector<double> angular;
  for (size_t i = 0; i < n; ++i) angular.push_back(loop.spacing / std::max(1e-9, (loop.points[i] - scanner).norm()));
  std::nth_element(angular.begin(), angular.begin() + static_cast<long>(n / 2), angular.end());
  const double cell = std::max({1e-5, angular[n / 2], angularGridStep(scene, scanner)});
  const DirectionMap seen(scene, scanner, cell);
  // The scene less the mesh's own samples and those beside them (three spacings): a
  // return among these at the sail's range, beyond its boundary, is more sail the mesh
  // does not hold. Seen obliquely, the mesh's own edge lies in the same directions.
  std::vector<Vec3> apart;
  {
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    const double near2 = std::pow(3.0 * loop.spacing, 2);
    for (const Vec3& q : scene) {
      samples.tree.nearest(q, 1, idx, d2);
      if (d2.empty() || d2[0] > near2) apart.push_back(q);
    }
  }
  const DirectionMap beyond_mesh(apart, scanner, cell);
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
    else if (s.incidence_deg >= p.grazing_incidence_deg - 2.0 * p.scanner_position_sigma_m / s.range_m * kDegPerRad)
      s.stop = Stop::Grazing;
    if (s.stop != Stop::Edge || scene.empty()) continue;
    // Two spacings beyond the boundary, outwards across it on the surface: the beam
    // there met something standing clear of the sail (ten spacings nearer the scanner,
    // beyond the sail's own samples around it: a spar, a stay, another sail).
    const Vec3 tangent = loop.points[(i + 1) % n] - loop.points[(i + n - 1) % n];
    Vec3 out = tangent.cross(normal.dot(loop.normal) < 0 ? Vec3(-normal) : normal);
    if (out.norm() < 1e-12) continue;
    out.normalize();
    enum class Beam { Clear, Blocked, Sail };
    auto probe = [&](double beyond_m, double& met) {
      const Vec3 to = loop.points[i] + beyond_m * out - scanner;
      met = seen.nearest(to.normalized());
      if (met < to.norm() - 10.0 * loop.spacing) return Beam::Blocked;
      const double other = beyond_mesh.nearest(to.normalized());
      return other < to.norm() + 10.0 * loop.spacing ? Beam::Sail : Beam::Clear;
    };
    double met = 0;
    const Beam first = probe(2.0 * loop.spacing, met);
    if (first != Beam::Blocked) {
      // More of the scene lies where the sail would go on, at its range: the sail's own
      // samples the surface left out (too sparse or too noisy to mesh), when they go on
      // for half a metre (beyond a spar's or a stay's width) or sixteen spacings. From
      // four spacings out: the scene's samples within three of the mesh are its own.
      bool goes_on = true;
      const double reach = std::max(16.0 * loop.spacing, 0.5);
      for (double w = 4.0 * loop.spacing; goes_on && w <= 2.0 * reach; w *= 2.0)
        goes_on = probe(std::min(w, reach), met) == Beam::Sail;
      if (goes_on) s.stop = Stop::LeftOut;
      continue;
    }
    // A narrow shadow (a stay, a mast seen beside a sail's head) that ends within the
    // corner's neighbourhood, beyond which the beams meet neither anything nearer nor
    // more of the scene off the mesh where the sail would go on (a strip of it cut off
    // by the shadow), holds the edge within its width.
    s.stop = Stop::Shadow;
    s.shadow_range_m = met;
    for (double w = 3.0 * loop.spacing; w <= around; w += loop.spacing) {
      const Beam beam = probe(w, met);
      if (beam == Beam::Blocked) continue;
      if (beam == Beam::Clear) {
        s.stop = Stop::Edge;
        s.bracket_m = w;
      }
      break;
    }
  }
  return stops;
}

// Why the samples stop, in words: `value` is the nearest thing in the way's range
// (Shadow, m), the farthest range (Range, m) or the widest incidence (Grazing, °).
std::string stopReason(Stop stop, double value, const OutlineParams& p) {
  switch (stop) {
    case Stop::Shadow:
      return "the samples stop at the shadow of something " + formatFixed(value, 1) +
             " m from the scanner, between it and the sail";
    case Stop::Range:
      return "the samples stop " + formatFixed(value, 1) + " m from the scanner, at the end of its " +
             formatFixed(p.scanner_max_range_m, 0) + " m range";
    case Stop::Grazing:
      return "the samples stop where the beams meet the cloth at up to " + formatFixed(value, 0) +
             "° incidence (beyond " + formatFixed(p.grazing_incidence_deg, 0) +
             "° the cloth returns less and less, and nothing at grazing angles)";
    case Stop::LeftOut:
      return "the sail's samples go on beyond the surface built from them (too sparse or too noisy there to mesh)";
    case Stop::Edge: break;
  }
  return "the samples stop at the sail's edge";
}

double edgeFraction(const std::vector<BoundaryStop>& stops, const std::vector<size_t>& idx) {
  if (idx.empty()) return 0;
  size_t edge = 0;
  for (size_t i : idx) edge += stops[i].stop == Stop::Edge;
  return static_cast<double>(edge) / static_cast<double>(idx.size());
}

// The stop that most of `count` boundary points short of the sail's edge share (by
// counts per Stop), or Edge when at most half of them are short of it. Shadow first,
// then range, grazing and left out on ties: the more specific reason.
Stop mostlyShortOfEdge(const size_t (&counts)[kStopKinds], size_t count) {
  const size_t edge = counts[static_cast<size_t>(Stop::Edge)];
  if (2 * (count - edge) <= count) return Stop::Edge;
  Stop most = Stop::Shadow;
  for (Stop k : {Stop::Range, Stop::Grazing, Stop::LeftOut})
    if (counts[static_cast<size_t>(k)] > counts[static_cast<size_t>(most)]) most = k;
  return most;
}

// Whether the samples reach the corner at loop index c: the boundary within `around`
// of it, on each side, is mostly where the sail ends. When not, the reason.
std::optional<std::string> notReached(const BoundaryLoop& loop, const std::vector<BoundaryStop>& stops, size_t c,
                                      double around, const char* name, const OutlineParams& p, double& bracket_m) {
  const size_t n = loop.size();
  bracket_m = 0;
  for (size_t dir : {size_t{1}, n - 1}) {
    size_t counts[kStopKinds] = {}, count = 0;
    double widest_deg = 0, farthest_m = 0, shadow_m = 0;
    for (size_t i = c, walked = 0; walked <= n / 2; i = (i + dir) % n, ++walked) {
      const double arc = std::abs(loop.cum[i] - loop.cum[c]);
      if (std::min(arc, loop.total - arc) > around) break;
      ++count;
      ++counts[static_cast<size_t>(stops[i].stop)];
      if (stops[i].stop == Stop::Shadow) shadow_m = std::max(shadow_m, stops[i].shadow_range_m);
      widest_deg = std::max(widest_deg, stops[i].incidence_deg);
      bracket_m = std::max(bracket_m, stops[i].bracket_m);
      farthest_m = std::max(farthest_m, stops[i].range_m);
    }
    const Stop most = mostlyShortOfEdge(counts, count);
    if (most == Stop::Edge) continue;
    const double value = most == Stop::Shadow ? shadow_m : most == Stop::Range ? farthest_m : widest_deg;
    return std::string("the ") + name + ": " + stopReason(most, value, p);
  }
  return std::nullopt;
}

}  // namespace

SailOutline::Coverage scanCoverage(const BoundaryLoop& loop, const NamedCorners& c, const Samples& samples,
                                   const Vec3& scanner, const std::vector<Vec3>& scene, const OutlineParams& p) {
  SailOutline::Coverage cov;
  cov.known = true;
  // A corner's neighbourhood: the stretch of boundary its turn is measured over.
  const double around = std::max(5.0 * loop.spacing, 0.02 * loop.total);
  const std::vector<BoundaryStop> stops = stopsAlongLoop(loop, samples, scanner, scene, around, p);
  for (const BoundaryStop& s : stops) cov.boundary_stop.push_back(s.stop);
  cov.luff = edgeFraction(stops, indicesBetween(loop, c, c.tack, c.head));
  cov.foot = edgeFraction(stops, indicesBetween(loop, c, c.tack, c.clew));
  cov.leech = edgeFraction(stops, indicesBetween(loop, c, c.clew, c.has_peak ? c.peak : c.head));
  if (c.has_peak) cov.top = edgeFraction(stops, indicesBetween(loop, c, c.head, c.peak));
  auto check = [&](size_t corner, const char* name, bool& reached, double& bracket_m) {
    if (auto why = notReached(loop, stops, corner, around, name, p, bracket_m)) {
      reached = false;
      cov.unreached.push_back(*why);
    }
  };
  check(c.tack, "tack", cov.tack, cov.tack_shadow_m);
  check(c.clew, "clew", cov.clew, cov.clew_shadow_m);
  check(c.head, "head", cov.head, cov.head_shadow_m);
  if (c.has_peak) check(c.peak, "peak", cov.peak, cov.peak_shadow_m);
  return cov;
}

}  // namespace sailshape::outline_internal

namespace sailshape {

std::optional<std::string> SailOutline::Coverage::shortOfEdgeNear(const std::vector<Vec3>& boundary,
                                                                  const Vec3& point) const {
  using namespace outline_internal;
  const size_t n = boundary.size();
  if (!known || boundary_stop.size() != n || n == 0) return std::nullopt;
  size_t nearest = 0;
  for (size_t i = 1; i < n; ++i)
    if ((boundary[i] - point).squaredNorm() < (boundary[nearest] - point).squaredNorm()) nearest = i;
  size_t counts[kStopKinds] = {};
  for (long k = -5; k <= 5; ++k) {
    const size_t i = (nearest + n + static_cast<size_t>(k + static_cast<long>(n))) % n;
    ++counts[static_cast<size_t>(boundary_stop[i])];
  }
  switch (mostlyShortOfEdge(counts, 11)) {
    case Stop::Shadow: return std::string("the samples stop at the shadow of something between the scanner and the sail");
    case Stop::Range: return std::string("the samples stop at the end of the scanner's range");
    case Stop::Grazing: return std::string("the samples stop where the beams meet the cloth at grazing incidence");
    case Stop::LeftOut: return stopReason(Stop::LeftOut, 0, OutlineParams{});
    case Stop::Edge: break;
  }
  return std::nullopt;
}

}  // namespace sailshape
