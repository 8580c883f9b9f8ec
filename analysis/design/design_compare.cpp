#include "analysis/design/design_compare.hpp"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <functional>
#include <map>
#include <random>
#include <utility>

#include "analysis/core/errors.hpp"
#include "analysis/spatial/principal_axes.hpp"
#include "analysis/surface/surface.hpp"

namespace sailshape {
namespace {

constexpr uint32_t kLeafTriangles = 4;  // 2 and 8 measured no faster

double percentile(const std::vector<double>& sorted, double q) {
  const double x = q * static_cast<double>(sorted.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(x));
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (x - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

SectionParameters minus(const SectionParameters& a, const SectionParameters& b) {
  SectionParameters d;
  d.chord_m = a.chord_m - b.chord_m;
  d.camber_pct = a.camber_pct - b.camber_pct;
  d.draft_pct = a.draft_pct - b.draft_pct;
  d.twist_deg = a.twist_deg - b.twist_deg;
  d.twist_rel_deg = a.twist_rel_deg - b.twist_rel_deg;
  d.entry_deg = a.entry_deg - b.entry_deg;
  d.exit_deg = a.exit_deg - b.exit_deg;
  return d;
}

}  // namespace

// Bounding volume hierarchy over the triangles: boxes split at the median
// centroid along their longest side, leaves of up to 4 triangles. A query
// visits the nearer child first and skips boxes farther than the best so far.
struct DesignDistance::Index {
  struct Node {
    Eigen::AlignedBox3d box;
    uint32_t first = 0, count = 0;  // leaf: triangles order[first, first + count)
    uint32_t left = 0, right = 0;   // inner node: children
  };
  std::vector<Node> nodes;
  std::vector<uint32_t> order;

  Index(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const std::vector<Vec3>& c,
        const std::vector<Vec3>& centroid) {
    order.resize(centroid.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    nodes.reserve(2 * order.size() / 4 + 2);
    build(0, static_cast<uint32_t>(order.size()), a, b, c, centroid);
  }

  uint32_t build(uint32_t first, uint32_t count, const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                 const std::vector<Vec3>& c, const std::vector<Vec3>& centroid) {
    const uint32_t id = static_cast<uint32_t>(nodes.size());
    nodes.emplace_back();
    Eigen::AlignedBox3d box, centres;
    for (uint32_t i = first; i < first + count; ++i) {
      const uint32_t t = order[i];
      box.extend(a[t]).extend(b[t]).extend(c[t]);
      centres.extend(centroid[t]);
    }
    nodes[id].box = box;
    if (count <= kLeafTriangles) {
      nodes[id].first = first;
      nodes[id].count = count;
      return id;
    }
    int axis = 0;
    centres.sizes().maxCoeff(&axis);
    const uint32_t half = count / 2;
    std::nth_element(order.begin() + first, order.begin() + first + half, order.begin() + first + count,
                     [&](uint32_t x, uint32_t y) { return centroid[x][axis] < centroid[y][axis]; });
    const uint32_t left = build(first, half, a, b, c, centroid);
    const uint32_t right = build(first + half, count - half, a, b, c, centroid);
    nodes[id].left = left;
    nodes[id].right = right;
    return id;
  }
};

Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  if (!std::isfinite(denom)) return a;  // degenerate triangle: its corners and edges were tried above
  return a + ab * (vb * denom) + ac * (vc * denom);
}

DesignDistance::DesignDistance(const Mesh& design) {
  if (design.triangles.empty()) throw InvalidInput("[DesignDistance] the design mesh has no triangles");
  const size_t nv = design.vertices.size(), nt = design.triangles.size();
  for (size_t t = 0; t < nt; ++t)
    for (uint32_t v : design.triangles[t])
      if (v >= nv)
        throw InvalidInput("[DesignDistance] triangle " + std::to_string(t) + " has vertex index " +
                           std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices)");
  a_.resize(nt);
  b_.resize(nt);
  c_.resize(nt);
  normal_.resize(nt);
  centroid_.resize(nt);
  std::vector<double> area(nt);
  std::map<std::pair<uint32_t, uint32_t>, int> edge_use;
  double total_area = 0;
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = design.triangles[t];
    a_[t] = design.vertices[tri[0]];
    b_[t] = design.vertices[tri[1]];
    c_[t] = design.vertices[tri[2]];
    centroid_[t] = (a_[t] + b_[t] + c_[t]) / 3.0;
    const Vec3 n = (b_[t] - a_[t]).cross(c_[t] - a_[t]);
    area[t] = 0.5 * n.norm();
    total_area += area[t];
    normal_[t] = area[t] > 0 ? Vec3(n.normalized()) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = tri[static_cast<size_t>(k)], w = tri[static_cast<size_t>((k + 1) % 3)];
      ++edge_use[{std::min(u, w), std::max(u, w)}];
    }
  }
  if (!(total_area > 0)) throw InvalidInput("[DesignDistance] the design mesh has zero area");

  // Leeward: the boundary spans the sail's "flat"; the cambered area bulges to one side of it.
  std::vector<char> on_boundary(nv, 0);
  for (const auto& [edge, uses] : edge_use)
    if (uses == 1) on_boundary[edge.first] = on_boundary[edge.second] = 1;
  std::vector<Vec3> rim;
  for (size_t v = 0; v < nv; ++v)
    if (on_boundary[v]) rim.push_back(design.vertices[v]);
  if (rim.size() < 3) {
    warnings_.push_back("the design mesh has no boundary: leeward taken from the plane fitted to all its vertices");
    rim = design.vertices;
  }
  const PrincipalAxes rim_plane = principalAxes(rim);
  Vec3 n = rim_plane.axes.col(0);
  const Vec3 origin = rim_plane.mean;
  double offset = 0;
  for (size_t t = 0; t < nt; ++t) offset += area[t] * (centroid_[t] - origin).dot(n);
  offset /= total_area;
  const double size = std::sqrt(total_area);
  cambered_ = std::abs(offset) > 1e-6 * size;
  if (cambered_) {
    if (offset < 0) n = -n;
  } else {
    // No side to bulge to: a fixed convention, port first.
    const double key = std::abs(n.y()) > 1e-9 ? n.y() : std::abs(n.z()) > 1e-9 ? n.z() : n.x();
    if (key < 0) n = -n;
    warnings_.push_back("the design is flat: distances are positive along its normal towards +Y (port), or +Z, +X");
  }
  leeward_ = n;
  for (Vec3& tn : normal_)
    if (tn.dot(leeward_) < 0) tn = -tn;
  index_ = std::make_unique<Index>(a_, b_, c_, centroid_);
}

DesignDistance::~DesignDistance() = default;

DesignDistance::Closest DesignDistance::closest(const Vec3& p) const {
  Closest best;
  double best_d2 = std::numeric_limits<double>::infinity();
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  const auto& nodes = index_->nodes;
  while (top > 0) {
    const Index::Node& n = nodes[stack[--top]];
    if (n.box.squaredExteriorDistance(p) >= best_d2) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const uint32_t t = index_->order[i];
        const Vec3 q = closestPointOnTriangle(p, a_[t], b_[t], c_[t]);
        const double d2 = (p - q).squaredNorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          best.point = q;
          best.triangle = t;
        }
      }
      continue;
    }
    // Push the farther child first so the nearer one is searched first.
    const double dl = nodes[n.left].box.squaredExteriorDistance(p), dr = nodes[n.right].box.squaredExteriorDistance(p);
    if (dl < dr) {
      if (dr < best_d2) stack[top++] = n.right;
      stack[top++] = n.left;
    } else {
      if (dl < best_d2) stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  const double d = std::sqrt(best_d2);
  best.distance_m = (p - best.point).dot(normal_[best.triangle]) < 0 ? -d : d;
  return best;
}

DistanceStats distanceStats(const std::vector<double>& d) {
  if (d.empty()) throw InvalidInput("[distanceStats] no distances");
  DistanceStats s;
  s.count = d.size();
  double sum = 0, sum2 = 0;
  for (double v : d) {
    sum += v;
    sum2 += v * v;
    s.max_abs_m = std::max(s.max_abs_m, std::abs(v));
  }
  s.mean_m = sum / static_cast<double>(d.size());
  s.rms_m = std::sqrt(sum2 / static_cast<double>(d.size()));
  std::vector<double> sorted = d;
  std::sort(sorted.begin(), sorted.end());
  s.p5_m = percentile(sorted, 0.05);
  s.p50_m = percentile(sorted, 0.50);
  s.p95_m = percentile(sorted, 0.95);
  return s;
}

std::vector<double> signedDistances(const DesignDistance& design, const std::vector<Vec3>& points,
                                    const Progress& progress) {
  std::vector<double> out(points.size());
  const long n = static_cast<long>(points.size());
  const long chunk = 16384;
  for (long start = 0; start < n; start += chunk) {
    const long end = std::min(n, start + chunk);
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = start; i < end; ++i)
      out[static_cast<size_t>(i)] = design.signedDistance(points[static_cast<size_t>(i)]);
    progress("distances", static_cast<double>(end) / static_cast<double>(n));
  }
  return out;
}

BoundaryCount countBoundary(const Mesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> use;
  for (const auto& t : mesh.triangles)
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t u = t[k], w = t[(k + 1) % 3];
      ++use[{std::min(u, w), std::max(u, w)}];
    }
  // Loops = connected components of the boundary edges (union–find on their vertices).
  std::map<uint32_t, uint32_t> parent;
  std::function<uint32_t(uint32_t)> root = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  BoundaryCount c;
  for (const auto& [e, n] : use) {
    if (n != 1) continue;
    ++c.edges;
    for (uint32_t v : {e.first, e.second}) parent.try_emplace(v, v);
    parent[root(e.first)] = root(e.second);
  }
  for (const auto& [v, p] : parent)
    if (v == p) ++c.loops;
  return c;
}

Cloud sampleMesh(const Mesh& mesh, size_t points, uint64_t seed) {
  if (mesh.triangles.empty()) throw InvalidInput("[sampleMesh] the mesh has no triangles");
  if (points == 0) throw InvalidInput("[sampleMesh] points must be > 0");
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (uint32_t v : mesh.triangles[t])
      if (v >= mesh.vertices.size())
        throw InvalidInput("[sampleMesh] triangle " + std::to_string(t) + " has vertex index " + std::to_string(v) +
                           " out of range (" + std::to_string(mesh.vertices.size()) + " vertices)");
    total += 0.5 * ((mesh.vertices[mesh.triangles[t][1]] - mesh.vertices[mesh.triangles[t][0]])
                        .cross(mesh.vertices[mesh.triangles[t][2]] - mesh.vertices[mesh.triangles[t][0]]))
                       .norm();
    cdf.push_back(total);
  }
  if (!(total > 0)) throw InvalidInput("[sampleMesh] the mesh has zero area");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  Cloud cloud;
  cloud.points.reserve(points);
  for (size_t i = 0; i < points; ++i) {
    const size_t t = std::min(static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), U(rng) * total) - cdf.begin()),
                              cdf.size() - 1);
    const auto& tri = mesh.triangles[t];
    const double r1 = std::sqrt(U(rng)), r2 = U(rng);  // uniform over the triangle
    cloud.points.push_back((1 - r1) * mesh.vertices[tri[0]] + r1 * (1 - r2) * mesh.vertices[tri[1]] +
                           r1 * r2 * mesh.vertices[tri[2]]);
  }
  return cloud;
}

double plausibleTrimDeviationM(const Mesh& design) {
  const double area = meshArea(design);
  Eigen::AlignedBox3d box;
  for (const Vec3& v : design.vertices) box.extend(v);
  const double height = box.isEmpty() ? 0 : box.sizes().z();
  if (!(area > 0) || !(height > 0))
    throw InvalidInput("[plausibleTrimDeviationM] the design has no area or no height (area " + std::to_string(area) +
                       " m², height " + std::to_string(height) + " m)");
  return 0.2 * area / height;
}

MeshSections analyzeMeshSections(const Mesh& mesh, const OutlineParams& outline, const SectionParams& sections,
                                 const MeshSampling& sampling) {
  if (sampling.mode != "auto" && sampling.mode != "mesh" && sampling.mode != "resample")
    throw InvalidInput("[analyzeMeshSections] sampling mode must be auto, mesh or resample (got '" + sampling.mode + "')");
  MeshSections r;
  const BoundaryCount b = countBoundary(mesh);
  r.resampled = sampling.mode == "resample" ||
                (sampling.mode == "auto" && (b.loops != 1 || b.edges < sampling.min_boundary_edges));
  if (!r.resampled) {
    r.outline = extractOutline(mesh, outline);
    r.sections = cutSections(mesh, r.outline, sections);
    return r;
  }
  r.notes.push_back("mesh resampled for the analysis: " + std::to_string(b.edges) + " boundary edges in " +
                    std::to_string(b.loops) + " loop(s); " + std::to_string(sampling.points) +
                    " uniform samples meshed again");
  const Mesh resampled = resampleMesh(mesh, sampling);
  r.outline = extractOutline(resampled, outline);
  r.sections = cutSections(resampled, r.outline, sections);
  return r;
}

Mesh resampleMesh(const Mesh& mesh, const MeshSampling& sampling) {
  SurfaceParams sp;
  sp.projection = "plane";
  return reconstructSurface(sampleMesh(mesh, sampling.points, sampling.seed), sp).mesh;
}

std::vector<SectionDelta> sectionDeltas(const SectionAnalysis& design, const SectionAnalysis& flying) {
  // The fractions each analysis was asked for, measured or not.
  auto asked = [](const SectionAnalysis& a) {
    std::vector<double> f;
    for (const Section& x : a.sections) f.push_back(x.fraction);
    for (const UnmeasuredSection& x : a.unmeasured) f.push_back(x.fraction);
    std::sort(f.begin(), f.end());
    return f;
  };
  auto list = [](const std::vector<double>& f) {
    std::string s;
    for (double x : f) s += (s.empty() ? "" : ", ") + std::to_string(x);
    return "[" + s + "]";
  };
  const std::vector<double> fd = asked(design), ff = asked(flying);
  bool same = fd.size() == ff.size();
  for (size_t i = 0; same && i < fd.size(); ++i) same = std::abs(fd[i] - ff[i]) < 1e-9;
  if (!same) throw InvalidInput("[sectionDeltas] design sections at " + list(fd) + " but flying sections at " + list(ff));
  // Sections measured on both; one left unmeasured on either side has no delta.
  std::vector<SectionDelta> out;
  for (const Section& ds : design.sections)
    for (const Section& fs : flying.sections)
      if (std::abs(ds.fraction - fs.fraction) < 1e-9) {
        SectionDelta d;
        d.fraction = ds.fraction;
        d.design = ds.value;
        d.flying = fs.value;
        out.push_back(d);
      }
  // twist_rel on both sides from the lowest section they share, whichever each
  // analysis measured lowest.
  for (SectionDelta& d : out) {
    d.design.twist_rel_deg = d.design.twist_deg - out.front().design.twist_deg;
    d.flying.twist_rel_deg = d.flying.twist_deg - out.front().flying.twist_deg;
    d.delta = minus(d.flying, d.design);
  }
  return out;
}

DesignComparison compareWithDesign(const Mesh& design, const SectionAnalysis& design_sections,
                                   const std::vector<Vec3>& flying_points, const SectionAnalysis& flying_sections,
                                   const Progress& progress) {
  if (flying_points.empty()) throw InvalidInput("[compareWithDesign] no flying points");
  DesignComparison c;
  c.sections = sectionDeltas(design_sections, flying_sections);
  const DesignDistance distance(design);
  c.leeward = distance.leeward();
  c.warnings = distance.warnings();
  c.distance_m = signedDistances(distance, flying_points, progress);
  c.stats = distanceStats(c.distance_m);
  return c;
}

}  // namespace sailshape
