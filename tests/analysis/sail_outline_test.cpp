// The outline on meshes whose boundary is known by construction: a regularly
// triangulated rectangle (a square-top sail's shape) in the vertical x-z plane.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/errors.hpp"
#include "analysis/sail_outline.hpp"
#include "tests/analysis/fixtures.hpp"

namespace sailshape {
namespace {

constexpr double kSpacing = 0.05;        // m between grid vertices
constexpr int kCellsX = 40, kCellsZ = 80;  // 2 m wide (x), 4 m high (z)

// Vertex (i, j) at x = i·spacing, z = j·spacing; two triangles per cell except
// the cells in `hole` (a rectangle of cells, empty when lo > hi).
Mesh rectangle(int hole_lo = 1, int hole_hi = 0) {
  Mesh m;
  for (int j = 0; j <= kCellsZ; ++j)
    for (int i = 0; i <= kCellsX; ++i) m.vertices.emplace_back(i * kSpacing, 0.0, j * kSpacing);
  auto v = [](int i, int j) { return static_cast<uint32_t>(j * (kCellsX + 1) + i); };
  for (int j = 0; j < kCellsZ; ++j)
    for (int i = 0; i < kCellsX; ++i) {
      if (i >= hole_lo && i <= hole_hi && j >= hole_lo && j <= hole_hi) continue;
      m.triangles.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      m.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
  return m;
}

bool onRectangleEdge(const Vec3& p) {
  const double w = kCellsX * kSpacing, h = kCellsZ * kSpacing, eps = 1e-9;
  return std::abs(p.x()) < eps || std::abs(p.x() - w) < eps || std::abs(p.z()) < eps || std::abs(p.z() - h) < eps;
}

TEST(SailOutline, BoundaryOfARectangleIsItsOuterLoopWithFourCorners) {
  // A hole of 10 x 10 cells: a second boundary loop, shorter than the outer one.
  const SailOutline o = extractOutline(rectangle(15, 24));
  // Every grid vertex on the rectangle's edges, once: 2 (40 + 80) of them.
  ASSERT_EQ(o.boundary.size(), static_cast<size_t>(2 * (kCellsX + kCellsZ)));
  for (const Vec3& p : o.boundary) EXPECT_TRUE(onRectangleEdge(p)) << p.transpose();
  EXPECT_NEAR(o.boundary_spacing_m, kSpacing, 1e-12);
  // Square top: tack forward (larger x) at the foot, head forward at the top.
  ASSERT_TRUE(o.has_peak);
  const double w = kCellsX * kSpacing, h = kCellsZ * kSpacing;
  // The corners are sampled exactly; the fitted edges may move them by up to a spacing.
  EXPECT_LT((o.tack - Vec3(w, 0, 0)).norm(), kSpacing);
  EXPECT_LT((o.clew - Vec3(0, 0, 0)).norm(), kSpacing);
  EXPECT_LT((o.head - Vec3(w, 0, h)).norm(), kSpacing);
  EXPECT_LT((o.peak - Vec3(0, 0, h)).norm(), kSpacing);
  EXPECT_NEAR(o.luff_length_m, h, kSpacing);
  EXPECT_NEAR(o.foot_length_m, w, kSpacing);
}

TEST(SailOutline, ATriangleNamingAMissingVertexIsRejected) {
  Mesh m = rectangle();
  m.triangles.push_back({0, 1, 99999});
  expectInvalidInput([&] { extractOutline(m); }, {"[extractOutline]", "vertex 99999", "3321 vertices"});
}

TEST(SailOutline, AClosedSurfaceHasNoBoundary) {
  Mesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};  // a tetrahedron, faces outward
  EXPECT_THROW(extractOutline(m), AnalysisError);
}

}  // namespace
}  // namespace sailshape
