#include "acquisition/ray_caster.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/core/errors.hpp"

namespace sailshape {

namespace {

constexpr uint32_t kLeafTriangles = 4;
constexpr int kSahDepth = 40;  // the traversal stack holds 64 levels

// Slab test; inv holds 1/direction (±inf for zero components, where `parallel` is set and 0 · inf on a
// slab face needs care). t_enter is where the ray enters the box (0 when it starts inside).
bool hitsBox(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv, bool parallel, double t_max,
             double& t_enter) {
  double t0 = 0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - o[k]) * inv[k], b = (hi[k] - o[k]) * inv[k];
    if (a > b) std::swap(a, b);
    if (parallel) {
      if (std::isnan(a)) a = -std::numeric_limits<double>::infinity();
      if (std::isnan(b)) b = std::numeric_limits<double>::infinity();
    }
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  t_enter = t0;
  return true;
}

}  // namespace

RayCaster::RayCaster(const Scene& scene) {
  for (uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Mesh& m = scene.objects[o].mesh;
    for (uint32_t t = 0; t < m.triangles.size(); ++t) {
      const auto& tri = m.triangles[t];
      for (uint32_t v : tri)
        if (v >= m.vertices.size())
          throw InvalidInput("[RayCaster] object " + scene.objects[o].name + " triangle " + std::to_string(t) +
                             " indexes vertex " + std::to_string(v) + " of " + std::to_string(m.vertices.size()));
      const Vec3& a = m.vertices[tri[0]];
      const Vec3 e1 = m.vertices[tri[1]] - a, e2 = m.vertices[tri[2]] - a;
      if (e1.cross(e2).squaredNorm() == 0) continue;  // degenerate: cannot be hit
      tris_.push_back({a, e1, e2, o, t});
    }
  }
  if (tris_.empty()) throw InvalidInput("[RayCaster] the scene has no non-degenerate triangle");
  std::vector<Vec3> centroids(tris_.size());
  for (size_t i = 0; i < tris_.size(); ++i) centroids[i] = tris_[i].a + (tris_[i].e1 + tris_[i].e2) / 3.0;
  nodes_.reserve(2 * tris_.size() / kLeafTriangles + 1);
  build(0, static_cast<uint32_t>(tris_.size()), centroids, 0);
}

uint32_t RayCaster::build(uint32_t first, uint32_t count, std::vector<Vec3>& centroids, int depth) {
  const auto index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back(Node{Vec3::Zero(), Vec3::Zero(), 0, 0});
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Vec3 clo = lo, chi = hi;
  for (uint32_t i = first; i < first + count; ++i) {
    const Triangle& t = tris_[i];
    for (const Vec3& p : {t.a, Vec3(t.a + t.e1), Vec3(t.a + t.e2)}) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    clo = clo.cwiseMin(centroids[i]);
    chi = chi.cwiseMax(centroids[i]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  if (count <= kLeafTriangles || chi[axis] - clo[axis] <= 0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  std::vector<uint32_t> order(count);
  for (uint32_t i = 0; i < count; ++i) order[i] = first + i;
  uint32_t mid = first + count / 2;
  // The split a ray pays least for (surface-area heuristic over binned centroids): a wall's few large
  // triangles and a sail's many small ones end up in boxes of their own instead of one box spanning both.
  // Past kSahDepth, or with no split found, the median on the longest centroid axis keeps the depth bounded.
  constexpr int kBins = 16;
  const auto binOf = [&](uint32_t i, int k) {
    return std::min(kBins - 1, static_cast<int>((centroids[i][k] - clo[k]) / (chi[k] - clo[k]) * kBins));
  };
  int best_axis = -1, best_bin = 0;
  if (depth < kSahDepth) {
    const auto area = [](const Vec3& a, const Vec3& b) {
      const Vec3 e = (b - a).cwiseMax(0.0);
      return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    double best_cost = area(lo, hi) * count;  // as a leaf of all of them (what a split must beat)
    for (int k = 0; k < 3; ++k) {
      if (!(chi[k] - clo[k] > 0)) continue;
      Vec3 blo[kBins], bhi[kBins];
      uint32_t bn[kBins] = {};
      for (int b = 0; b < kBins; ++b) blo[b] = Vec3::Constant(std::numeric_limits<double>::infinity()), bhi[b] = -blo[b];
      for (uint32_t i = first; i < first + count; ++i) {
        const int b = binOf(i, k);
        const Triangle& t = tris_[i];
        for (const Vec3& p : {t.a, Vec3(t.a + t.e1), Vec3(t.a + t.e2)}) {
          blo[b] = blo[b].cwiseMin(p);
          bhi[b] = bhi[b].cwiseMax(p);
        }
        ++bn[b];
      }
      double right_cost[kBins] = {};
      Vec3 rlo = Vec3::Constant(std::numeric_limits<double>::infinity()), rhi = -rlo;
      uint32_t rn = 0;
      for (int b = kBins - 1; b > 0; --b) {
        rlo = rlo.cwiseMin(blo[b]);
        rhi = rhi.cwiseMax(bhi[b]);
        rn += bn[b];
        right_cost[b] = rn > 0 ? area(rlo, rhi) * rn : 0;
      }
      Vec3 llo = Vec3::Constant(std::numeric_limits<double>::infinity()), lhi = -llo;
      uint32_t ln = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        llo = llo.cwiseMin(blo[b]);
        lhi = lhi.cwiseMax(bhi[b]);
        ln += bn[b];
        if (ln == 0 || ln == count) continue;
        const double cost = area(llo, lhi) * ln + right_cost[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = k;
          best_bin = b;
        }
      }
    }
  }
  if (best_axis >= 0) {
    const auto split =
        std::partition(order.begin(), order.end(), [&](uint32_t i) { return binOf(i, best_axis) <= best_bin; });
    mid = first + static_cast<uint32_t>(split - order.begin());
  } else {
    std::nth_element(order.begin(), order.begin() + (mid - first), order.end(),
                     [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  }
  // Reorder the triangle range and its centroids together.
  std::vector<Triangle> tris(count);
  std::vector<Vec3> cents(count);
  for (uint32_t i = 0; i < count; ++i) {
    tris[i] = tris_[order[i]];
    cents[i] = centroids[order[i]];
  }
  std::copy(tris.begin(), tris.end(), tris_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids.begin() + first);
  build(first, mid - first, centroids, depth + 1);
  const uint32_t right = build(mid, first + count - mid, centroids, depth + 1);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

// Möller–Trumbore: the distance along unit d at which the ray meets the triangle, when nearer than t_best.
inline bool RayCaster::meets(const Triangle& t, const Vec3& origin, const Vec3& d, double min_m, double t_best,
                             double& dist) {
  const Vec3 pv = d.cross(t.e2);
  const double det = t.e1.dot(pv);
  if (std::abs(det) < 1e-14) return false;
  const double inv_det = 1.0 / det;
  const Vec3 tv = origin - t.a;
  const double u = tv.dot(pv) * inv_det;
  if (u < 0 || u > 1) return false;
  const Vec3 qv = tv.cross(t.e1);
  const double v = d.dot(qv) * inv_det;
  if (v < 0 || u + v > 1) return false;
  dist = t.e2.dot(qv) * inv_det;
  return dist > min_m && dist < t_best;
}

RayHit RayCaster::hitOf(const Triangle* t, double distance_m, const Vec3& d) {
  RayHit best;
  if (!t) return best;
  best.hit = true;
  best.distance_m = distance_m;
  best.object = t->object;
  best.triangle = t->index;
  Vec3 nrm = t->e1.cross(t->e2).normalized();
  if (nrm.dot(d) > 0) nrm = -nrm;
  best.normal = nrm;
  return best;
}

RayHit RayCaster::cast(const Vec3& origin, const Vec3& direction, double min_m, double max_m) const {
  RayHit hit;
  castBundle(&origin, &direction, 1, &hit, min_m, max_m);
  return hit;
}

void RayCaster::castBundle(const Vec3* origins, const Vec3* directions, size_t count, RayHit* out,
                           double min_m, double max_m) const {
  if (count > kMaxBundle) throw InvalidInput("[RayCaster::castBundle] at most " + std::to_string(kMaxBundle) +
                                             " rays share a traversal (got " + std::to_string(count) + ")");
  Vec3 d[kMaxBundle], inv[kMaxBundle];
  bool parallel[kMaxBundle];
  double t_best[kMaxBundle];
  const Triangle* hit[kMaxBundle];
  uint32_t live = 0;  // rays that can hit anything
  for (size_t r = 0; r < count; ++r) {
    out[r] = RayHit{};
    hit[r] = nullptr;
    t_best[r] = max_m;
    const double len = directions[r].norm();
    if (!(len > 0) || !origins[r].allFinite()) continue;
    d[r] = directions[r] / len;
    inv[r] = Vec3(1.0 / d[r].x(), 1.0 / d[r].y(), 1.0 / d[r].z());
    parallel[r] = !inv[r].allFinite();  // a zero (or denormal) direction component
    live |= 1u << r;
  }
  // Nodes still to visit, with the rays that entered each and where each entered it: a node a ray entered
  // beyond the nearest hit it found since the node was pushed holds nothing nearer for that ray, so its box
  // need not be tested again.
  struct Pending {
    uint32_t node, rays;
    double t_enter[kMaxBundle];
  };
  Pending stack[64];
  int top = 0;
  const auto test = [&](uint32_t node, uint32_t rays, Pending& p) {
    p.node = node;
    p.rays = 0;
    for (uint32_t r = 0; r < count; ++r)
      if ((rays >> r & 1u) &&
          hitsBox(nodes_[node].lo, nodes_[node].hi, origins[r], inv[r], parallel[r], t_best[r], p.t_enter[r]))
        p.rays |= 1u << r;
    return p.rays != 0;
  };
  if (live == 0 || !test(0, live, stack[0])) return;
  top = 1;
  while (top > 0) {
    Pending next = stack[--top];
    for (uint32_t r = 0; r < count; ++r)
      if ((next.rays >> r & 1u) && next.t_enter[r] > t_best[r]) next.rays &= ~(1u << r);
    if (next.rays == 0) continue;
    const Node& n = nodes_[next.node];
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i)
        for (uint32_t r = 0; r < count; ++r) {
          double dist;
          if ((next.rays >> r & 1u) && meets(tris_[i], origins[r], d[r], min_m, t_best[r], dist)) {
            t_best[r] = dist;
            hit[r] = &tris_[i];
          }
        }
      continue;
    }
    if (top + 2 > 64) throw AnalysisError("[RayCaster::castBundle] hierarchy deeper than 64 levels");
    const uint32_t left = static_cast<uint32_t>(&n - nodes_.data()) + 1, right = n.first;
    Pending l, rt;
    const bool hl = test(left, next.rays, l), hr = test(right, next.rays, rt);
    // The nearer child first (pushed last), as the first ray that entered both sees them.
    bool left_first = true;
    if (hl && hr)
      for (uint32_t r = 0; r < count; ++r)
        if (l.rays & rt.rays & (1u << r)) {
          left_first = l.t_enter[r] < rt.t_enter[r];
          break;
        }
    if (hl && hr) {
      stack[top++] = left_first ? rt : l;
      stack[top++] = left_first ? l : rt;
    } else if (hl) {
      stack[top++] = l;
    } else if (hr) {
      stack[top++] = rt;
    }
  }
  for (size_t r = 0; r < count; ++r) out[r] = hitOf(hit[r], t_best[r], d[r]);
}

}  // namespace sailshape
