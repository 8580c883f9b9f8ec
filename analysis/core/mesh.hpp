#pragma once
// Triangle meshes in SI units.
#include <array>
#include <cstdint>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

struct Mesh {
  std::vector<Vec3> vertices;                     // metres
  std::vector<std::array<uint32_t, 3>> triangles; // indices into vertices, counter-clockwise

  bool empty() const { return triangles.empty(); }
};

// Surface area in m².
double meshArea(const Mesh& mesh);

// Unit normal of triangle t (zero vector for a degenerate triangle).
Vec3 triangleNormal(const Mesh& mesh, size_t t);

// Area-weighted unit normal of each vertex (zero for a vertex of no triangle, or
// where its triangles' normals cancel), one per mesh.vertices entry.
std::vector<Vec3> vertexNormals(const Mesh& mesh);

}  // namespace sailshape
