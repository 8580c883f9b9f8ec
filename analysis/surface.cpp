#include "analysis/surface.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <numeric>

#include "analysis/errors.hpp"

namespace sailshape {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

std::vector<std::pair<Kernel::Point_2, uint32_t>> projectToPlane(const Cloud& cloud) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : cloud.points) mean += p;
  mean /= static_cast<double>(cloud.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& p : cloud.points) cov.noalias() += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Vec3 a = eig.eigenvectors().col(2), b = eig.eigenvectors().col(1);
  std::vector<std::pair<Kernel::Point_2, uint32_t>> pts;
  pts.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 d = cloud.points[i] - mean;
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

// Keeps the triangles of the largest edge-connected component (ties: the one
// holding the lowest triangle). Triangles sharing an edge are found by bucketing
// each edge under its lower vertex (counting sort: linear in the mesh).
size_t keepLargestComponent(std::vector<std::array<uint32_t, 3>>& tris, size_t vertices) {
  struct Half {
    uint32_t other, tri;
  };
  std::vector<uint32_t> start(vertices + 1, 0);
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) ++start[std::min(t[e], t[(e + 1) % 3]) + 1];
  for (size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
  std::vector<Half> halves(start[vertices]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t t = 0; t < tris.size(); ++t)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = tris[t][e], b = tris[t][(e + 1) % 3];
        halves[fill[std::min(a, b)]++] = {std::max(a, b), t};
      }
  }
  std::vector<uint32_t> parent(tris.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t v = 0; v < vertices; ++v)
    for (uint32_t i = start[v]; i < start[v + 1]; ++i)
      for (uint32_t j = start[v]; j < i; ++j)
        if (halves[j].other == halves[i].other) {
          parent[find(halves[i].tri)] = find(halves[j].tri);
          break;
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
    tris.push_back(t);
    for (int e = 0; e < 3; ++e) edge_len.push_back((cloud.points[t[e]] - cloud.points[t[(e + 1) % 3]]).norm());
  }
  result.delaunay_triangles = tris.size();
  if (tris.empty()) throw AnalysisError("[reconstructSurface] the points are collinear in the projection: no triangle");

  double max_edge = p.max_edge_m;
  if (max_edge == 0) {
    std::vector<double> sorted = edge_len;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    max_edge = p.max_edge_factor * sorted[sorted.size() / 2];
  }
  result.max_edge_m = max_edge;
  std::vector<std::array<uint32_t, 3>> kept;
  kept.reserve(tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    if (edge_len[3 * t] > max_edge || edge_len[3 * t + 1] > max_edge || edge_len[3 * t + 2] > max_edge)
      ++result.dropped_long_edges;
    else
      kept.push_back(tris[t]);
  }
  if (kept.empty())
    throw AnalysisError("[reconstructSurface] every triangle has an edge longer than max_edge_m = " +
                        std::to_string(max_edge) + " m");
  if (p.largest_component_only) result.dropped_small_components = keepLargestComponent(kept, cloud.size());

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
