#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape {
namespace outline_internal {
namespace {


// The simple loops a closed walk is made of: the walk cut at each vertex it
// returns to. A vertex may be passed more than once; each pass closes the loop
// since the last.
std::vector<std::vector<uint32_t>> simpleLoops(const std::vector<uint32_t>& walk) {
  std::vector<std::vector<uint32_t>> loops;
  std::vector<uint32_t> stack;
  std::unordered_map<uint32_t, size_t> at;  // vertex → its position on the stack
  for (uint32_t v : walk) {
    const auto it = at.find(v);
    if (it != at.end()) {
      const size_t from = it->second;
      loops.emplace_back(stack.begin() + static_cast<long>(from), stack.end());
      for (size_t i = from + 1; i < stack.size(); ++i) at.erase(stack[i]);
      stack.resize(from + 1);
      continue;
    }
    at[v] = stack.size();
    stack.push_back(v);
  }
  loops.push_back(std::move(stack));
  return loops;
}

}  // namespace

// The longest closed loop of boundary edges: directed edges a→b used by exactly
// one triangle whose reverse b→a no triangle uses. Edges are bucketed by their
// lower vertex (counting sort, linear in the mesh) instead of hashed: the mesh
// of a 200,000-point scan has 1.2 million directed edges.
std::vector<uint32_t> outerBoundaryLoop(const Mesh& mesh) {
  const size_t nv = mesh.vertices.size();
  // Each undirected edge under its lower vertex: the other vertex and whether the
  // triangle runs lower→higher.
  struct Half {
    uint32_t other;
    bool up;
  };
  std::vector<uint32_t> start(nv + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      if (std::max(a, b) >= nv)
        throw InvalidInput("[extractOutline] a triangle uses vertex " + std::to_string(std::max(a, b)) +
                           " of a mesh with " + std::to_string(nv) + " vertices");
      if (a != b) ++start[std::min(a, b) + 1];  // a self-edge is its own reverse: never a boundary
    }
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<Half> halves(start[nv]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& t : mesh.triangles)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t[e], b = t[(e + 1) % 3];
        if (a == b) continue;
        halves[fill[std::min(a, b)]++] = {std::max(a, b), a < b};
      }
  }
  // Boundary edges (from, to), in the order of their lower vertex.
  std::vector<std::pair<uint32_t, uint32_t>> boundary;
  for (uint32_t v = 0; v < nv; ++v) {
    const Half* h = halves.data() + start[v];
    const size_t m = start[v + 1] - start[v];
    for (size_t i = 0; i < m; ++i) {
      bool seen = false;  // this vertex pair already counted at an earlier slot
      for (size_t j = 0; j < i && !seen; ++j) seen = h[j].other == h[i].other;
      if (seen) continue;
      int up = 0, down = 0;
      for (size_t j = i; j < m; ++j)
        if (h[j].other == h[i].other) ++(h[j].up ? up : down);
      if (up == 1 && down == 0) boundary.emplace_back(v, h[i].other);
      if (down == 1 && up == 0) boundary.emplace_back(h[i].other, v);
    }
  }
  if (boundary.empty()) throw AnalysisError("[extractOutline] the mesh has no boundary edge (closed surface?)");
  // Outgoing boundary edges of each vertex: out_to[out_start[v] .. out_start[v + 1]).
  std::vector<uint32_t> out_start(nv + 1, 0), out_to(boundary.size());
  for (const auto& [a, b] : boundary) ++out_start[a + 1];
  for (size_t v = 0; v < nv; ++v) out_start[v + 1] += out_start[v];
  {
    std::vector<uint32_t> fill(out_start.begin(), out_start.end() - 1);
    for (const auto& [a, b] : boundary) out_to[fill[a]++] = b;
  }
  std::vector<char> used(boundary.size(), 0);
  std::vector<uint32_t> best, loop;
  double best_len = -1;
  for (uint32_t from = 0; from < nv; ++from)
    for (uint32_t first_edge = out_start[from]; first_edge < out_start[from + 1]; ++first_edge) {
      if (used[first_edge]) continue;
      loop.assign(1, from);
      uint32_t edge = first_edge;
      bool closed = false;
      while (true) {
        used[edge] = 1;
        const uint32_t nxt = out_to[edge];
        if (nxt == from) {
          closed = true;
          break;
        }
        loop.push_back(nxt);
        bool found = false;
        for (uint32_t e = out_start[nxt]; e < out_start[nxt + 1] && !found; ++e)
          if (!used[e]) {
            edge = e;
            found = true;
          }
        if (!found || loop.size() > boundary.size()) break;
      }
      if (!closed || loop.size() < 3) continue;
      // A hole that touches the outline at one vertex (where two triangles meet
      // only at their tips) joins the walk there: the walk goes round the hole
      // and back out. Each simple loop of the walk is a candidate on its own; a
      // hole's excursion kept in the outline is a deep notch whose turn reads as
      // a corner (a clew found in mid-luff).
      for (const std::vector<uint32_t>& simple : simpleLoops(loop)) {
        if (simple.size() < 3) continue;
        double len = 0;
        for (size_t i = 0; i < simple.size(); ++i)
          len += (mesh.vertices[simple[i]] - mesh.vertices[simple[(i + 1) % simple.size()]]).norm();
        if (len > best_len) {
          best_len = len;
          best = simple;
        }
      }
    }
  if (best.empty()) throw AnalysisError("[extractOutline] the mesh boundary does not form a closed loop");
  return best;
}

Vec3 BoundaryLoop::pointAt(double s) const {
  s = std::fmod(s, total);
  if (s < 0) s += total;
  const size_t i = static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin()) - 1;
  const size_t j = (i + 1) % points.size();
  const double seg = (i + 1 < cum.size() ? cum[i + 1] : total) - cum[i];
  const double t = seg > 0 ? (s - cum[i]) / seg : 0.0;
  return points[i] + t * (points[j] - points[i]);
}

BoundaryLoop boundaryLoop(const Mesh& mesh) {
  BoundaryLoop loop;
  std::vector<Vec3>& pts = loop.points;
  loop.vertex = outerBoundaryLoop(mesh);
  for (uint32_t v : loop.vertex) pts.push_back(mesh.vertices[v]);
  const size_t n = pts.size();
  std::vector<double> seg(n);
  loop.cum.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) seg[i] = (pts[(i + 1) % n] - pts[i]).norm();
  for (size_t i = 1; i < n; ++i) loop.cum[i] = loop.cum[i - 1] + seg[i - 1];
  loop.total = loop.cum[n - 1] + seg[n - 1];
  std::nth_element(seg.begin(), seg.begin() + static_cast<long>(n / 2), seg.end());
  loop.spacing = seg[n / 2];
  for (size_t i = 0; i < n; ++i) loop.normal += pts[i].cross(pts[(i + 1) % n]);
  return loop;
}

// The area between two polylines running the same way (an edge's sampled
// boundary `a` and its outline `b`): triangles zipped between them by their arc
// fractions, each counted outwards where `b` lies to the right of `a` seen from
// `up` (outside the sail, for a boundary running anticlockwise about `up`) and
// inwards where to the left (noise across an edge leaves samples beyond it).
double ribbonArea(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& up) {
  if (a.size() < 2 || b.size() < 2) return 0;
  auto fractions = [](const std::vector<Vec3>& line) {
    std::vector<double> f(line.size(), 0.0);
    for (size_t i = 1; i < line.size(); ++i) f[i] = f[i - 1] + (line[i] - line[i - 1]).norm();
    for (double& x : f) x /= std::max(f.back(), 1e-12);
    return f;
  };
  const std::vector<double> fa = fractions(a), fb = fractions(b);
  double area = 0;
  for (size_t i = 0, j = 0; i + 1 < a.size() || j + 1 < b.size();) {
    // Twice the triangle's vector area: it points against `up` when b lies to the right.
    Vec3 c;
    if (j + 1 >= b.size() || (i + 1 < a.size() && fa[i + 1] <= fb[j + 1])) {
      c = (a[i + 1] - a[i]).cross(b[j] - a[i]);
      ++i;
    } else {
      c = (b[j + 1] - a[i]).cross(b[j] - a[i]);
      ++j;
    }
    area -= 0.5 * std::copysign(c.norm(), c.dot(up));
  }
  return area;
}

}  // namespace outline_internal

double polylineLength(const std::vector<Vec3>& line) {
  double len = 0;
  for (size_t i = 1; i < line.size(); ++i) len += (line[i] - line[i - 1]).norm();
  return len;
}

Vec3 pointAtFraction(const std::vector<Vec3>& line, double fraction) {
  if (line.empty()) throw InvalidInput("[pointAtFraction] empty polyline");
  if (line.size() == 1) return line[0];
  const double target = std::clamp(fraction, 0.0, 1.0) * polylineLength(line);
  double acc = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const double seg = (line[i] - line[i - 1]).norm();
    if (acc + seg >= target && seg > 0) return line[i - 1] + (target - acc) / seg * (line[i] - line[i - 1]);
    acc += seg;
  }
  return line.back();
}

}  // namespace sailshape
