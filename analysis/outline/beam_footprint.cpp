// The scanner's beam footprint at the sail's edges (OutlineParams beam_*): a return
// lies on the sail only while the whole footprint does, so the samples stop short
// of every edge by the footprint's reach across it, and the edges and corners move
// out by that.
#include <algorithm>
#include <cmath>

#include "analysis/core/units.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {

// How far the beam's footprint reaches from its axis across the surface at p
// (unit normal n) in the surface direction w (unit), for a scanner at `origin`: the
// beam's radius there, exit/2 + range·divergence/2, and in the plane of incidence
// that over cos(incidence) (capped at 80°, beyond which nothing returns).
double footprintReach(const OutlineParams& p, const Vec3& origin, const Vec3& at, const Vec3& n, const Vec3& w) {
  const Vec3 d = at - origin;
  const double range = d.norm();
  if (!(range > 0)) return 0;
  const double radius = 0.5 * p.beam_exit_diameter_m + 0.5 * range * p.beam_divergence_rad;
  const Vec3 ray = d / range;
  const double cos_i = std::max(std::abs(ray.dot(n)), std::cos(80.0 * kPi / 180.0));
  const Vec3 along = ray - ray.dot(n) * n;  // the ray's direction in the surface
  const double c = along.norm() > 1e-9 ? w.dot(along.normalized()) : 0.0;
  const double tan2 = (1.0 - cos_i * cos_i) / (cos_i * cos_i);
  return radius * std::sqrt(1.0 + tan2 * c * c);
}

// How far a corner moves when each of its edges a and b (meeting at `corner`, each
// starting there when *_start) moves out by the beam's footprint: x with x·(−in_a) =
// s_a and x·(−in_b) = s_b, in the corner's plane (far along the bisector at a narrow
// head: several times the footprint). The edges' directions are taken over a tenth
// of their length: the corner curves' own tangents where they meet, extrapolated
// past the samples, may close in, and a narrower angle would move the corner
// further still. Zero where the edges are parallel.
Vec3 footprintShift(const OutlineParams& p, const Vec3& scanner, const Vec3& corner, const Edge& a, bool a_start,
                    const Edge& b, bool b_start, double spacing) {
  const Vec3 ta = edgeChord(a, a_start, corner, spacing), tb = edgeChord(b, b_start, corner, spacing);
  const Vec3 across_a = tb - tb.dot(ta) * ta, across_b = ta - ta.dot(tb) * tb;
  const Vec3 plane_normal = ta.cross(tb);
  if (!(plane_normal.norm() > 1e-3 && across_a.norm() > 1e-6 && across_b.norm() > 1e-6)) return Vec3::Zero();
  const Vec3 n = plane_normal.normalized(), in_a = across_a.normalized(), in_b = across_b.normalized();
  const double s_a = footprintReach(p, scanner, corner, n, -in_a);
  const double s_b = footprintReach(p, scanner, corner, n, -in_b);
  const double cc = in_a.dot(in_b), det = std::max(1.0 - cc * cc, 1e-6);
  return ((-s_a + cc * s_b) * in_a + (-s_b + cc * s_a) * in_b) / det;
}

double moveOutByFootprint(std::vector<Vec3>& line, double& sigma, const OutlineParams& p, const Vec3& scanner,
                          const Samples& samples) {
  if (line.size() < 3) return 0.0;
  std::vector<Vec3> moved = line;
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  double sum = 0;
  for (size_t i = 1; i + 1 < line.size(); ++i) {
    const Vec3 t = (line[i + 1] - line[i - 1]).normalized();
    const Vec3 in = acrossAt(line[i], line[i], t, samples, idx, d2).in;
    const double s = footprintReach(p, scanner, line[i], t.cross(in).normalized(), -in);
    moved[i] = line[i] - s * in;
    sum += s;
  }
  line = std::move(moved);
  const double mean = sum / static_cast<double>(line.size() - 2);
  sigma = std::hypot(sigma, kFootprintUncertainty * mean);
  return mean;
}

}  // namespace sailshape::outline_internal
