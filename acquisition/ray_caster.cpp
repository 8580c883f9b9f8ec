#include "acquisition/ray_caster.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/errors.hpp"

namespace sailshape {

namespace {

constexpr uint32_t kLeafTriangles = 4;

// Slab test; inv holds 1/direction (±inf for zero components).
bool hitsBox(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv, double t_max, double& t_enter) {
  double t0 = 0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - o[k]) * inv[k], b = (hi[k] - o[k]) * inv[k];
    if (a > b) std::swap(a, b);
    if (std::isnan(a)) a = -std::numeric_limits<double>::infinity();  // 0 · inf on a slab face
    if (std::isnan(b)) b = std::numeric_limits<double>::infinity();
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
  build(0, static_cast<uint32_t>(tris_.size()), centroids);
}

uint32_t RayCaster::build(uint32_t first, uint32_t count, std::vector<Vec3>& centroids) {
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
  // Median split by centroid: sort the triangle range and its centroids together.
  const uint32_t mid = first + count / 2;
  std::vector<uint32_t> order(count);
  for (uint32_t i = 0; i < count; ++i) order[i] = first + i;
  std::nth_element(order.begin(), order.begin() + (mid - first), order.end(),
                   [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
  std::vector<Triangle> tris(count);
  std::vector<Vec3> cents(count);
  for (uint32_t i = 0; i < count; ++i) {
    tris[i] = tris_[order[i]];
    cents[i] = centroids[order[i]];
  }
  std::copy(tris.begin(), tris.end(), tris_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids.begin() + first);
  build(first, mid - first, centroids);
  const uint32_t right = build(mid, first + count - mid, centroids);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

RayHit RayCaster::cast(const Vec3& origin, const Vec3& direction, double min_m, double max_m) const {
  RayHit best;
  const double len = direction.norm();
  if (!(len > 0) || !origin.allFinite()) return best;
  const Vec3 d = direction / len;
  const Vec3 inv(1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z());
  double t_best = max_m;
  const Triangle* hit = nullptr;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    double t_enter;
    if (!hitsBox(n.lo, n.hi, origin, inv, t_best, t_enter)) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const Triangle& t = tris_[i];
        const Vec3 pv = d.cross(t.e2);
        const double det = t.e1.dot(pv);
        if (std::abs(det) < 1e-14) continue;
        const double inv_det = 1.0 / det;
        const Vec3 tv = origin - t.a;
        const double u = tv.dot(pv) * inv_det;
        if (u < 0 || u > 1) continue;
        const Vec3 qv = tv.cross(t.e1);
        const double v = d.dot(qv) * inv_det;
        if (v < 0 || u + v > 1) continue;
        const double dist = t.e2.dot(qv) * inv_det;
        if (dist > min_m && dist < t_best) {
          t_best = dist;
          hit = &t;
        }
      }
      continue;
    }
    // Visit the nearer child first (pushed last).
    const uint32_t left = static_cast<uint32_t>(&n - nodes_.data()) + 1, right = n.first;
    double tl = 0, tr = 0;
    const bool hl = hitsBox(nodes_[left].lo, nodes_[left].hi, origin, inv, t_best, tl);
    const bool hr = hitsBox(nodes_[right].lo, nodes_[right].hi, origin, inv, t_best, tr);
    if (top + 2 > 64) throw AnalysisError("[RayCaster::cast] hierarchy deeper than 64 levels");
    if (hl && hr) {
      stack[top++] = tl < tr ? right : left;
      stack[top++] = tl < tr ? left : right;
    } else if (hl) {
      stack[top++] = left;
    } else if (hr) {
      stack[top++] = right;
    }
  }
  if (hit) {
    best.hit = true;
    best.distance_m = t_best;
    best.object = hit->object;
    best.triangle = hit->index;
    Vec3 nrm = hit->e1.cross(hit->e2).normalized();
    if (nrm.dot(d) > 0) nrm = -nrm;
    best.normal = nrm;
  }
  return best;
}

}  // namespace sailshape
