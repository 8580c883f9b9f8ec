#include "analysis/surface/surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A tilted frame, so nothing lines up with the axes.
const Eigen::Matrix3d& tilt() {
  static const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.4, Vec3::UnitZ()) * Eigen::AngleAxisd(0.7, Vec3(1, 1, 0).normalized())).toRotationMatrix();
  return r;
}

// An n × m grid with spacing h starting at x0 in the plane z = 0 of the tilted frame;
// point (i, j) has index offset + i*m + j.
void addGrid(Cloud& cloud, int n, int m, double h, double x0) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) cloud.points.push_back(tilt() * Vec3(x0 + i * h, j * h, 0.0) + Vec3(1, 2, 3));
}

TEST(ReconstructSurface, ARegularGridGivesTwoTrianglesPerCell) {
  const int n = 30, m = 20;
  const double h = 0.05;
  Cloud cloud;
  addGrid(cloud, n, m, h, 0.0);
  const Surface s = reconstructSurface(cloud);
  EXPECT_EQ(s.projection, "plane");  // auto, without scan angles
  // A Delaunay triangulation of V points with B on the convex hull has 2V − B − 2
  // triangles: with V = nm and B = 2(n + m) − 4 that is 2(n − 1)(m − 1).
  const size_t expected = 2u * (n - 1) * (m - 1);
  EXPECT_EQ(s.delaunay_triangles, expected);
  EXPECT_EQ(s.mesh.triangles.size(), expected);
  EXPECT_EQ(s.dropped_long_edges, 0u);
  EXPECT_EQ(s.dropped_small_components, 0u);
  EXPECT_TRUE(s.warnings.empty());
  // Edges are h, h and the diagonal √2·h: the median is h, the default threshold 4h.
  EXPECT_NEAR(s.max_edge_m, 4 * h, 1e-12);
  // Every point is a vertex, in input order, unmoved.
  ASSERT_EQ(s.mesh.vertices.size(), cloud.size());
  std::vector<uint32_t> identity(cloud.size());
  std::iota(identity.begin(), identity.end(), 0u);
  EXPECT_EQ(s.vertex_source, identity);
  EXPECT_EQ(s.mesh.vertices, cloud.points);
  // The mesh covers the grid's rectangle exactly, each triangle half a cell, consistently oriented.
  EXPECT_NEAR(meshArea(s.mesh), (n - 1) * (m - 1) * h * h, 1e-9);
  const Vec3 normal = tilt() * Vec3::UnitZ();
  const double first = triangleNormal(s.mesh, 0).dot(normal);
  EXPECT_NEAR(std::abs(first), 1.0, 1e-9);
  for (size_t t = 0; t < s.mesh.triangles.size(); ++t) {
    EXPECT_NEAR(triangleNormal(s.mesh, t).dot(normal), first, 1e-9) << t;
    const auto& tri = s.mesh.triangles[t];
    const Vec3 &a = s.mesh.vertices[tri[0]], &b = s.mesh.vertices[tri[1]], &c = s.mesh.vertices[tri[2]];
    EXPECT_NEAR(0.5 * (b - a).cross(c - a).norm(), 0.5 * h * h, 1e-12) << t;
  }
}

TEST(ReconstructSurface, LongEdgesAcrossAGapAreTrimmedAndTheSmallPieceDropped) {
  // A 20 × 20 and a 10 × 10 grid (h = 5 cm) in one plane, 0.5 m apart: every triangle
  // spanning the gap has an edge ≥ 0.5 m, far over the 4h = 0.2 m threshold.
  const double h = 0.05;
  Cloud cloud;
  addGrid(cloud, 20, 20, h, 0.0);
  addGrid(cloud, 10, 10, h, 19 * h + 0.5);
  const size_t big = 2u * 19 * 19, small = 2u * 9 * 9;

  const Surface s = reconstructSurface(cloud);
  EXPECT_NEAR(s.max_edge_m, 4 * h, 1e-12);
  EXPECT_GT(s.dropped_long_edges, 0u);
  EXPECT_EQ(s.mesh.triangles.size(), big);
  EXPECT_EQ(s.dropped_small_components, small);
  EXPECT_EQ(s.delaunay_triangles, big + small + s.dropped_long_edges);
  // Only the big grid's 400 points remain, in input order.
  ASSERT_EQ(s.vertex_source.size(), 400u);
  for (uint32_t i = 0; i < 400; ++i) EXPECT_EQ(s.vertex_source[i], i);
  EXPECT_NEAR(meshArea(s.mesh), 19 * 19 * h * h, 1e-9);
  for (size_t t = 0; t < s.mesh.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e)
      EXPECT_LE((s.mesh.vertices[s.mesh.triangles[t][e]] - s.mesh.vertices[s.mesh.triangles[t][(e + 1) % 3]]).norm(),
                s.max_edge_m);
  // 100 of the 500 points (20 % > 5 %) are in no triangle.
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("100 of 500 points"), std::string::npos) << s.warnings[0];

  SurfaceParams keep_all;
  keep_all.largest_component_only = false;
  const Surface both = reconstructSurface(cloud, keep_all);
  EXPECT_EQ(both.mesh.triangles.size(), big + small);
  EXPECT_EQ(both.dropped_small_components, 0u);
  EXPECT_EQ(both.dropped_long_edges, s.dropped_long_edges);
  EXPECT_EQ(both.mesh.vertices.size(), 500u);
  EXPECT_TRUE(both.warnings.empty());

  // An explicit threshold over the gap keeps the bridging triangles.
  SurfaceParams wide;
  wide.max_edge_m = 10.0;
  const Surface bridged = reconstructSurface(cloud, wide);
  EXPECT_EQ(bridged.max_edge_m, 10.0);
  EXPECT_EQ(bridged.dropped_long_edges, 0u);
  EXPECT_EQ(bridged.mesh.triangles.size(), bridged.delaunay_triangles);
}

// A scanner at the origin sweeping a sphere of radius 5 m around it: α (mirror angle)
// over [40°, 140°] and β (turntable) over [−100°, 100°], 4° steps. The surface wraps 200°
// around the turntable axis, like an off-wind sail seen from inside, so no plane sees it
// without folding. Point (i, j) has index i*nb + j.
struct WrappedScan {
  Cloud cloud;
  int na = 26, nb = 51;
};

WrappedScan wrappedScan() {
  WrappedScan w;
  const double r = 5.0;
  for (int i = 0; i < w.na; ++i)
    for (int j = 0; j < w.nb; ++j) {
      const double a = (40.0 + 4.0 * i) * kRadPerDeg, b = (-100.0 + 4.0 * j) * kRadPerDeg;
      // SPEC §2 with p = 0: X = r cos α, Y = r sin α cos β, Z = r sin α sin β.
      w.cloud.points.emplace_back(r * std::cos(a), r * std::sin(a) * std::cos(b), r * std::sin(a) * std::sin(b));
      w.cloud.alpha_rad.push_back(a);
      w.cloud.beta_rad.push_back(b);
    }
  return w;
}

TEST(ReconstructSurface, ScanAnglesTriangulateAWrappedSurfaceAsItsScanGrid) {
  const WrappedScan w = wrappedScan();
  const Surface s = reconstructSurface(w.cloud);  // auto: the cloud has scan angles
  EXPECT_EQ(s.projection, "scan_angles");
  const size_t expected = 2u * (w.na - 1) * (w.nb - 1);
  EXPECT_EQ(s.delaunay_triangles, expected);
  EXPECT_EQ(s.mesh.triangles.size(), expected);
  EXPECT_EQ(s.dropped_long_edges, 0u);
  EXPECT_EQ(s.mesh.vertices.size(), w.cloud.size());
  // Every triangle joins neighbours of the scan grid: half a grid cell.
  for (const auto& t : s.mesh.triangles) {
    int imin = w.na, imax = -1, jmin = w.nb, jmax = -1;
    for (uint32_t v : t) {
      const int i = static_cast<int>(s.vertex_source[v]) / w.nb, j = static_cast<int>(s.vertex_source[v]) % w.nb;
      imin = std::min(imin, i), imax = std::max(imax, i), jmin = std::min(jmin, j), jmax = std::max(jmax, j);
    }
    EXPECT_EQ(imax - imin, 1);
    EXPECT_EQ(jmax - jmin, 1);
  }
  // The area is that of the spherical band: r² Δβ (cos α0 − cos α1), less the chordal
  // sag of 4° facets (relative (Δθ)²/12 per direction ≈ 0.1 %).
  const double band = 25.0 * (200 * kRadPerDeg) * (std::cos(40 * kRadPerDeg) - std::cos(140 * kRadPerDeg));
  EXPECT_NEAR(meshArea(s.mesh), band, 0.005 * band);

  SurfaceParams plane;
  plane.projection = "plane";
  const Surface folded = reconstructSurface(w.cloud, plane);
  EXPECT_EQ(folded.projection, "plane");
  // Projected on a plane the wrapped band folds over itself: triangles join its two
  // sides across metres and are trimmed, and the grid is not recovered.
  EXPECT_GT(folded.dropped_long_edges, 0u);
  EXPECT_LT(folded.mesh.triangles.size(), expected);
}

TEST(ReconstructSurface, ReportsProgress) {
  Cloud cloud;
  addGrid(cloud, 5, 5, 0.1, 0.0);
  std::vector<double> fractions;
  Progress progress;
  progress.callback = [&](std::string_view stage, double f) {
    EXPECT_EQ(stage, "surface");
    fractions.push_back(f);
  };
  reconstructSurface(cloud, SurfaceParams{}, progress);
  EXPECT_EQ(fractions, (std::vector<double>{0.5, 1.0}));
}

TEST(ReconstructSurface, RejectsBadInputs) {
  Cloud two;
  two.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  expectThrowWith<InvalidInput>([&] { reconstructSurface(two); },
                                {"[reconstructSurface]", "need at least 3 points (got 2)"});
  Cloud grid;
  addGrid(grid, 4, 4, 0.1, 0.0);
  SurfaceParams p;
  p.projection = "cylinder";
  expectThrowWith<InvalidInput>([&] { reconstructSurface(grid, p); }, {"[reconstructSurface]", "'cylinder'"});
  p = SurfaceParams{};
  p.projection = "scan_angles";
  expectThrowWith<InvalidInput>([&] { reconstructSurface(grid, p); }, {"[reconstructSurface]", "alpha_rad and beta_rad"});
  for (double bad : {-0.1, std::nan("")}) {
    p = SurfaceParams{};
    p.max_edge_m = bad;
    expectThrowWith<InvalidInput>([&] { reconstructSurface(grid, p); }, {"[reconstructSurface]", "max_edge_m"});
  }
  for (double bad : {0.0, -1.0, std::nan("")}) {
    p = SurfaceParams{};
    p.max_edge_factor = bad;
    expectThrowWith<InvalidInput>([&] { reconstructSurface(grid, p); }, {"[reconstructSurface]", "max_edge_factor"});
  }
  // Scan angles that do not cover every point cannot be projected.
  WrappedScan w = wrappedScan();
  w.cloud.beta_rad.pop_back();
  expectThrowWith<InvalidInput>([&] { reconstructSurface(w.cloud); },
                                {"[reconstructSurface]", "1326 alpha_rad", "1325 beta_rad", "1326 points"});
}

TEST(ReconstructSurface, ThrowsAnalysisErrorWhenNoTriangleSurvives) {
  Cloud line;
  for (int i = 0; i < 10; ++i) line.points.emplace_back(0.1 * i, 0.2 * i, -0.05 * i);
  expectThrowWith<AnalysisError>([&] { reconstructSurface(line); }, {"[reconstructSurface]", "collinear"});

  Cloud grid;
  addGrid(grid, 4, 4, 0.1, 0.0);
  SurfaceParams p;
  p.max_edge_m = 0.05;  // shorter than the 0.1 m grid spacing
  expectThrowWith<AnalysisError>([&] { reconstructSurface(grid, p); },
                                 {"[reconstructSurface]", "every triangle has an edge longer than max_edge_m = 0.05"});
}

}  // namespace
}  // namespace sailshape
