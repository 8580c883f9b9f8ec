#pragma once
// Ray–triangle casting against a Scene through a bounding-volume hierarchy
// (binned surface-area-heuristic splits, Möller–Trumbore per triangle).
// A sweep is hundreds of scan lines × ~1000 beams × a few footprint rays, so
// each query is O(log n) and allocation-free; queries are const and thread-safe.
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "acquisition/scene.hpp"

namespace sailshape {

struct RayHit {
  bool hit = false;
  double distance_m = std::numeric_limits<double>::infinity();  // along the unit direction
  uint32_t object = 0;     // index into Scene::objects
  uint32_t triangle = 0;   // index into that object's mesh
  Vec3 normal = Vec3::Zero();  // unit geometric normal of the triangle hit, facing the ray
};

class RayCaster {
 public:
  // Copies the triangles it needs; the scene may go away afterwards.
  explicit RayCaster(const Scene& scene);

  // Nearest hit along origin + t·direction for t in (min_m, max_m]; direction need not be unit.
  RayHit cast(const Vec3& origin, const Vec3& direction, double min_m = 1e-6,
              double max_m = std::numeric_limits<double>::infinity()) const;

  // The nearest hits of `count` (≤ kMaxBundle) rays at once, out[i] as cast(origins[i], directions[i])
  // gives it, in one traversal of the hierarchy (cast is a bundle of one): for a beam's footprint, rays
  // that stay close together, the nodes are visited once for all of them.
  static constexpr size_t kMaxBundle = 8;
  void castBundle(const Vec3* origins, const Vec3* directions, size_t count, RayHit* out, double min_m = 1e-6,
                  double max_m = std::numeric_limits<double>::infinity()) const;

  size_t triangleCount() const { return tris_.size(); }
  size_t nodeCount() const { return nodes_.size(); }

 private:
  struct Triangle {
    Vec3 a, e1, e2;  // vertex a and edges b − a, c − a
    uint32_t object, index;
  };
  struct Node {
    Eigen::Vector3d lo, hi;
    uint32_t first;  // leaf: first triangle; inner: index of the right child (left child = this + 1)
    uint32_t count;  // > 0 for a leaf
  };
  uint32_t build(uint32_t first, uint32_t count, std::vector<Vec3>& centroids, int depth);
  static bool meets(const Triangle& t, const Vec3& origin, const Vec3& d, double min_m, double t_best, double& dist);
  static RayHit hitOf(const Triangle* t, double distance_m, const Vec3& d);

  std::vector<Triangle> tris_;
  std::vector<Node> nodes_;
};

}  // namespace sailshape
