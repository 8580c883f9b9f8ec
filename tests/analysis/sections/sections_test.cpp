// Plane cuts of a mesh (analysis/sections.cpp): the points a section curve is
// made of, on a surface whose every point is known.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/core/errors.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/core/units.hpp"
#include "analysis/sections/sections.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A closed ring of a circular cylinder about +Z: `columns` vertices round each of
// `rows` + 1 circles from z = 0 to `height`, each quad split by the same diagonal.
// Every vertex lies on the cylinder; the facets are chords of it.
Mesh cylinderRing(double radius, double height, int columns, int rows) {
  Mesh mesh;
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j < columns; ++j) {
      const double a = 2.0 * kPi * j / columns;
      mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), height * i / rows);
    }
  auto v = [&](int i, int j) { return static_cast<uint32_t>(i * columns + (j % columns)); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < columns; ++j) {
      mesh.triangles.push_back({v(i, j), v(i, j + 1), v(i + 1, j + 1)});
      mesh.triangles.push_back({v(i, j), v(i + 1, j + 1), v(i + 1, j)});
    }
  return mesh;
}

TEST(PlaneCuts, PointsLieOnTheCurvedSurfaceNotOnItsFlatFacets) {
  // 24 columns: facets 15° of arc wide. A plane across the middle row crosses its
  // upright edges (straight lines of the cylinder) and its diagonals, a helix each,
  // whose straight chord passes up to R(1 − cos 7.5°) = 12.8 mm inside the cylinder.
  // The middle row's vertices have triangles all round, so their normals are the
  // cylinder's own; the curved edges follow the helix to a few hundredths of that.
  const double radius = 1.5, height = 1.0;
  const int columns = 24;
  const Mesh mesh = cylinderRing(radius, height, columns, 3);
  const double flat_sag = radius * (1.0 - std::cos(kPi / columns));
  ASSERT_NEAR(flat_sag, 0.0128, 1e-4);
  for (const Vec3& normal : {Vec3(0, 0, 1), Vec3(0.1, 0.05, 1)}) {
    SCOPED_TRACE("plane normal " + std::to_string(normal.x()) + " " + std::to_string(normal.y()));
    const Vec3 point(0, 0, 0.5 * height);
    const auto cuts = planeCuts(mesh, point, normal);
    ASSERT_EQ(cuts.size(), 1u);  // one closed loop round the ring
    const std::vector<Vec3>& loop = cuts[0];
    ASSERT_GE(loop.size(), static_cast<size_t>(2 * columns));
    double worst = 0;
    for (const Vec3& q : loop) {
      EXPECT_NEAR(normal.normalized().dot(q - point), 0.0, 1e-9);  // in the plane
      worst = std::max(worst, std::abs(std::hypot(q.x(), q.y()) - radius));
    }
    EXPECT_LT(worst, 0.05 * flat_sag);
  }
}

TEST(PlaneCuts, APlaneThatMissesTheMeshCutsNothing) {
  const Mesh mesh = cylinderRing(1.0, 1.0, 12, 2);
  EXPECT_TRUE(planeCuts(mesh, Vec3(0, 0, 2), Vec3::UnitZ()).empty());
}

TEST(PlaneCuts, AZeroOrNonFiniteNormalIsRefused) {
  const Mesh mesh = cylinderRing(1.0, 1.0, 12, 2);
  for (const Vec3& n : {Vec3(0, 0, 0), Vec3(0, std::nan(""), 1)})
    expectInvalidInput([&] { planeCuts(mesh, Vec3(0, 0, 0.5), n); },
                       {"[planeCuts] the plane's normal must be finite and non-zero"});
}

}  // namespace
}  // namespace sailshape
