#include "analysis/core/mesh.hpp"

#include <Eigen/Geometry>
#include <string>

#include "analysis/core/errors.hpp"

namespace sailshape {

namespace {

// The three corners of triangle t, checked against the vertex count.
std::array<Vec3, 3> corners(const Mesh& mesh, size_t t, const char* function) {
  std::array<Vec3, 3> c;
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = mesh.triangles[t][k];
    if (v >= mesh.vertices.size())
      throw InvalidInput(std::string("[") + function + "] triangle " + std::to_string(t) + " has vertex index " +
                         std::to_string(v) + " (mesh has " + std::to_string(mesh.vertices.size()) + " vertices)");
    c[k] = mesh.vertices[v];
  }
  return c;
}

}  // namespace

double meshArea(const Mesh& mesh) {
  double area = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto c = corners(mesh, t, "meshArea");
    area += 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).norm();
  }
  return area;
}

Vec3 triangleNormal(const Mesh& mesh, size_t t) {
  if (t >= mesh.triangles.size())
    throw InvalidInput("[triangleNormal] triangle " + std::to_string(t) + " out of range (mesh has " +
                       std::to_string(mesh.triangles.size()) + " triangles)");
  const auto c = corners(mesh, t, "triangleNormal");
  const Vec3 e1 = c[1] - c[0];
  const Vec3 e2 = c[2] - c[0];
  const Vec3 n = e1.cross(e2);
  const double norm = n.norm();
  // Collinear corners leave only rounding noise in the cross product: |e1×e2| = |e1||e2| sin(angle).
  if (!(norm > 1e-12 * e1.norm() * e2.norm())) return Vec3::Zero();
  return n / norm;
}

std::vector<Vec3> vertexNormals(const Mesh& mesh) {
  std::vector<Vec3> n(mesh.vertices.size(), Vec3::Zero());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto c = corners(mesh, t, "vertexNormals");
    const Vec3 fn = (c[1] - c[0]).cross(c[2] - c[0]);  // twice the area, along the normal
    for (uint32_t v : mesh.triangles[t]) n[v] += fn;
  }
  for (Vec3& v : n)
    if (v.norm() > 0) v.normalize();
  return n;
}

}  // namespace sailshape
