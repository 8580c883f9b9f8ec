#include "analysis/surface/surface.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "analysis/core/errors.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
// Each face keeps its triangle's index (kNoTriangle for slivers) for the component search.
using FaceBase = CGAL::Triangulation_face_base_with_info_2<uint32_t, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;
constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();

std::vector<std::pair<Kernel::Point_2, uint32_t>> projectToPlane(const Cloud& cloud) {
  const PrincipalAxes pa = principalAxes(cloud.points);
  const Vec3 a = pa.axes.col(2), b = pa.axes.col(1);
  std::vector<std::pair<Kernel::Point_2, uint32_t>> pts;
  pts.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 d = cloud.points[i] - pa.mean;
    pts.emplace_back(Kernel::Point_2(d.dot(a), d.dot(b)), static_cast<uint32_t>(i));
  }
  return pts;
}

std::vector<std::pair<Kernel::Point_2, uint32_t>> projectToScanAngles(const Cloud& cloud) {
  std::vector<std::pair<Kernel::Point_2, uint32_t>> pts;
  pts.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i)
    pts.emplace_back(Kernel::Point_2(cloud.alpha_rad[i], cloud.beta_rad[i]), static_cast<uint32_t>(i));
  return pts;
}

// Keeps the triangles of the largest edge-connected component of `kept` (ties: the
// one holding the lowest triangle). Triangles sharing an edge are neighbouring faces
// of the triangulation: face f holds triangle f->info() of the Delaunay list, kept
// as slot[f->info()] (kNoTriangle: dropped).
size_t keepLargestComponent(const Delaunay& dt, const std::vector<uint32_t>& slot,
                            std::vector<std::array<uint32_t, 3>>& tris) {
  std::vector<uint32_t> parent(tris.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    const uint32_t t = f->info();
    if (t == kNoTriangle || slot[t] == kNoTriangle) continue;
    for (int e = 0; e < 3; ++e) {
      const auto nb = f->neighbor(e);
      if (dt.is_infinite(nb)) continue;
      const uint32_t u = nb->info();
      if (u < t && slot[u] != kNoTriangle) parent[find(slot[t])] = find(slot[u]);
    }
  }
  std::vector<uint32_t> count(tris.size(), 0);
  std::vector<uint32_t> root(tris.size());
  for (uint32_t t = 0; t < tris.size(); ++t) ++count[root[t] = find(t)];
  // Triangles are visited in index order, so the first root reaching the largest
  // count strictly is the component holding the lowest triangle among the largest.
  uint32_t best = root[0];
  for (uint32_t t = 0; t < tris.size(); ++t)
    if (count[root[t]] > count[best]) best = root[t];
  std::vector<std::array<uint32_t, 3>> kept;
  kept.reserve(count[best]);
  for (uint32_t t = 0; t < tris.size(); ++t)
    if (root[t] == best) kept.push_back(tris[t]);
  const size_t dropped = tris.size() - kept.size();
  tris.swap(kept);
  return dropped;
}

// The (n/2)-th smallest of the non-negative values v (what nth_element puts at n/2),
// from a histogram of 4,096 bins and a selection within the one bin that holds it.
double medianOf(const std::vector<double>& v) {
  double hi = 0;
  for (double x : v) hi = std::max(hi, x);
  if (!(hi > 0)) return hi;
  constexpr int kBins = 4096;
  const double scale = kBins / hi;
  auto binOf = [&](double x) { return std::min(kBins - 1, static_cast<int>(x * scale)); };
  std::vector<uint32_t> count(kBins, 0);
  for (double x : v) ++count[static_cast<size_t>(binOf(x))];
  const size_t want = v.size() / 2;
  size_t below = 0;
  int b = 0;
  while (below + count[static_cast<size_t>(b)] <= want) below += count[static_cast<size_t>(b++)];
  std::vector<double> part;
  part.reserve(count[static_cast<size_t>(b)]);
  for (double x : v)
    if (binOf(x) == b) part.push_back(x);
  std::nth_element(part.begin(), part.begin() + static_cast<long>(want - below), part.end());
  return part[want - below];
}

}  // namespace

Surface reconstructSurface(const Cloud& cloud, const SurfaceParams& p, const Progress& progress) {
  if (cloud.size() < 3)
    throw InvalidInput("[reconstructSurface] need at least 3 points (got " + std::to_string(cloud.size()) + ")");
  if (p.projection != "auto" && p.projection != "plane" && p.projection != "scan_angles")
    throw InvalidInput("[reconstructSurface] projection must be auto, plane or scan_angles (got '" + p.projection +
                       "')");
  if (!(p.max_edge_m >= 0) || !(p.max_edge_factor > 0))
    throw InvalidInput("[reconstructSurface] max_edge_m must be >= 0 and max_edge_factor > 0 (got " +
                       std::to_string(p.max_edge_m) + " and " + std::to_string(p.max_edge_factor) + ")");
  Surface result;
  result.projection = p.projection == "auto" ? (cloud.hasScanAngles() ? "scan_angles" : "plane") : p.projection;
  if (result.projection == "scan_angles" && !cloud.hasScanAngles())
    throw InvalidInput("[reconstructSurface] projection scan_angles needs per-point alpha_rad and beta_rad");
  if (result.projection == "scan_angles" &&
      (cloud.alpha_rad.size() != cloud.size() || cloud.beta_rad.size() != cloud.size()))
    throw InvalidInput("[reconstructSurface] projection scan_angles needs alpha_rad and beta_rad for every point (got " +
                       std::to_string(cloud.alpha_rad.size()) + " alpha_rad, " + std::to_string(cloud.beta_rad.size()) +
                       " beta_rad for " + std::to_string(cloud.size()) + " points)");

  auto projected = result.projection == "plane" ? projectToPlane(cloud) : projectToScanAngles(cloud);
  Delaunay dt;
  dt.insert(projected.begin(), projected.end());
  progress("surface", 0.5);

  std::vector<std::array<uint32_t, 3>> tris;
  tris.reserve(static_cast<size_t>(dt.number_of_faces()));
  std::vector<double> edge_len;
  edge_len.reserve(static_cast<size_t>(dt.number_of_faces()) * 3);
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    f->info() = kNoTriangle;
    // Points that should be collinear (a straight boundary of a regular scan) come out of
    // the projection a rounding error apart, and the triangulation joins them into
    // zero-area slivers along the hull: no surface, no normal. Skip faces whose height is
    // below 1e-9 of their longest edge.
    const Kernel::Point_2 &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
    const double twice_area = std::abs((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
    const double longest2 = std::max({CGAL::squared_distance(a, b), CGAL::squared_distance(b, c),
                                      CGAL::squared_distance(c, a)});
    if (twice_area <= 1e-9 * longest2) continue;
    std::array<uint32_t, 3> t{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    f->info() = static_cast<uint32_t>(tris.size());
    tris.push_back(t);
    for (int e = 0; e < 3; ++e) edge_len.push_back((cloud.points[t[e]] - cloud.points[t[(e + 1) % 3]]).norm());
  }
  result.delaunay_triangles = tris.size();
  if (tris.empty()) throw AnalysisError("[reconstructSurface] the points are collinear in the projection: no triangle");

  double max_edge = p.max_edge_m;
  if (max_edge == 0) max_edge = p.max_edge_factor * medianOf(edge_len);
  result.max_edge_m = max_edge;
  std::vector<std::array<uint32_t, 3>> kept;
  kept.reserve(tris.size());
  std::vector<uint32_t> slot(tris.size(), kNoTriangle);  // triangle -> its place in `kept`
  for (size_t t = 0; t < tris.size(); ++t) {
    if (edge_len[3 * t] > max_edge || edge_len[3 * t + 1] > max_edge || edge_len[3 * t + 2] > max_edge) {
      ++result.dropped_long_edges;
    } else {
      slot[t] = static_cast<uint32_t>(kept.size());
      kept.push_back(tris[t]);
    }
  }
  if (kept.empty())
    throw AnalysisError("[reconstructSurface] every triangle has an edge longer than max_edge_m = " +
                        std::to_string(max_edge) + " m");
  if (p.largest_component_only) result.dropped_small_components = keepLargestComponent(dt, slot, kept);

  // Compact: mesh vertices are the used input points, in input order.
  std::vector<uint32_t> remap(cloud.size(), std::numeric_limits<uint32_t>::max());
  for (const auto& t : kept)
    for (uint32_t v : t) remap[v] = 0;
  for (uint32_t i = 0; i < cloud.size(); ++i)
    if (remap[i] == 0) {
      remap[i] = static_cast<uint32_t>(result.mesh.vertices.size());
      result.mesh.vertices.push_back(cloud.points[i]);
      result.vertex_source.push_back(i);
    }
  // Triangles keep the Delaunay (counter-clockwise in the projection) orientation.
  result.mesh.triangles.reserve(kept.size());
  for (const auto& t : kept) result.mesh.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  const size_t unused = cloud.size() - result.mesh.vertices.size();
  if (unused > cloud.size() / 20)
    result.warnings.push_back(std::to_string(unused) + " of " + std::to_string(cloud.size()) +
                              " points are in no triangle (holes, long edges or separate pieces)");
  progress("surface", 1.0);
  return result;
}

}  // namespace sailshape
