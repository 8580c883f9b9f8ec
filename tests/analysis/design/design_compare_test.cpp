#include "analysis/design/design_compare.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

// A grid mesh over (s, t) ∈ [−1, 1]² placed by `at`.
template <class F>
Mesh gridMesh(int n, F at) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) m.vertices.push_back(at(-1.0 + 2.0 * i / n, -1.0 + 2.0 * j / n));
  auto id = [n](int i, int j) { return static_cast<uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

double bruteForceDistance(const Mesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles)
    best = std::min(best, (p - closestPointOnTriangle(p, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]])).norm());
  return best;
}

TEST(DesignCompare, ClosestPointOnTriangleInEveryRegion) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  EXPECT_EQ(closestPointOnTriangle(Vec3(0.5, 0.5, 3), a, b, c), Vec3(0.5, 0.5, 0));  // face
  EXPECT_EQ(closestPointOnTriangle(Vec3(-1, -1, 1), a, b, c), a);                    // vertex regions
  EXPECT_EQ(closestPointOnTriangle(Vec3(3, -1, 0), a, b, c), b);
  EXPECT_EQ(closestPointOnTriangle(Vec3(-1, 3, 0), a, b, c), c);
  EXPECT_EQ(closestPointOnTriangle(Vec3(1, -2, 0), a, b, c), Vec3(1, 0, 0));   // edge ab
  EXPECT_EQ(closestPointOnTriangle(Vec3(-2, 1, 5), a, b, c), Vec3(0, 1, 0));   // edge ac
  EXPECT_EQ(closestPointOnTriangle(Vec3(2, 2, -1), a, b, c), Vec3(1, 1, 0));   // edge bc
  // Degenerate (collinear) triangle: the closest point on its segment.
  EXPECT_NEAR((closestPointOnTriangle(Vec3(1, 1, 0), a, b, Vec3(1, 0, 0)) - Vec3(1, 0, 0)).norm(), 0, 1e-15);
}

TEST(DesignCompare, SignedDistanceAboveATiltedPlaneIsExact) {
  // A flat panel 20° off vertical, facing port-ish: no camber, so the sign follows +Y.
  const Vec3 u = Vec3(1, 0, 0), w = Vec3(0, std::sin(20 * kRadPerDeg), std::cos(20 * kRadPerDeg));
  const Vec3 normal = u.cross(w);  // (0, −cos20, sin20): towards starboard, up
  const Mesh plane = gridMesh(7, [&](double s, double t) -> Vec3 { return Vec3(1, 2, 3) + 3.0 * s * u + 5.0 * t * w; });
  const DesignDistance dd(plane);
  EXPECT_FALSE(dd.cambered());
  ASSERT_EQ(dd.warnings().size(), 1u);
  EXPECT_NEAR((dd.leeward() - (-normal)).norm(), 0, 1e-12);  // +Y side
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-0.9, 0.9), H(-0.5, 0.5);
  for (int k = 0; k < 200; ++k) {
    const double h = H(rng);
    const Vec3 foot = Vec3(1, 2, 3) + 3.0 * U(rng) * u + 5.0 * U(rng) * w;
    const DesignDistance::Closest c = dd.closest(foot - h * normal);  // h to port
    ASSERT_NEAR(c.distance_m, h, 1e-12);
    ASSERT_NEAR((c.point - foot).norm(), 0, 1e-12);
  }
}

TEST(DesignCompare, SignedDistanceOffASphereCapWithinTheChordError) {
  // Cap of a sphere of radius R about the origin, its apex towards +Z (the side it bulges to).
  const double R = 5.0;
  const Mesh cap = gridMesh(120, [&](double s, double t) { return Vec3(s, t, std::sqrt(R * R - s * s - t * t)); });
  // Every vertex is on the sphere, so a triangle with circumradius ρ lies inside it by
  // at most R − √(R² − ρ²): the mesh is a shell [R − sag, R], and the distance from a
  // point at radius R + h to it is within sag of |h| (the radial ray crosses the shell).
  double rho_max = 0;
  for (const auto& t : cap.triangles) {
    const Vec3 a = cap.vertices[t[0]], b = cap.vertices[t[1]], c = cap.vertices[t[2]];
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
    rho_max = std::max(rho_max, la * lb * lc / (2.0 * (b - a).cross(c - a).norm()));
  }
  const double sag = R - std::sqrt(R * R - rho_max * rho_max);
  ASSERT_LT(sag, 0.5e-4);  // fine enough for the 0.1 mm target
  const DesignDistance dd(cap);
  EXPECT_TRUE(dd.cambered());
  EXPECT_GT(dd.leeward().z(), 0.999);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-0.8, 0.8), H(-0.3, 0.3);
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const double x = U(rng), y = U(rng), h = H(rng);
    const Vec3 dir = Vec3(x, y, std::sqrt(R * R - x * x - y * y)).normalized();
    const double d = dd.signedDistance((R + h) * dir);
    worst = std::max(worst, std::abs(d - h));
  }
  EXPECT_LE(worst, sag + 1e-12);
  EXPECT_LT(worst, 1e-4);
}

TEST(DesignCompare, AcceleratedSearchEqualsBruteForce) {
  const Mesh design = generateSailMesh(exampleDesign(SailType::Gennaker), 30, 16);
  const DesignDistance dd(design);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0, 1), N(-1.5, 1.5);
  const SailSurface surface(exampleDesign(SailType::Gennaker));
  for (int k = 0; k < 400; ++k) {
    // Near the sail and far from it (up to 1.5 m off on each axis).
    const Vec3 p = surface.at(U(rng), U(rng)) + (k % 2 ? 0.05 : 1.0) * Vec3(N(rng), N(rng), N(rng));
    ASSERT_NEAR(std::abs(dd.signedDistance(p)), bruteForceDistance(design, p), 1e-12) << k;
  }
}

TEST(DesignCompare, LeewardFollowsTheCamberOnEitherTack) {
  for (bool port : {true, false}) {
    SailDesign d = exampleDesign(SailType::Main);
    d.leeward_port = port;
    const Mesh mesh = generateSailMesh(d, 60, 30);
    const DesignDistance dd(mesh);
    EXPECT_TRUE(dd.cambered());
    EXPECT_GT(port ? dd.leeward().y() : -dd.leeward().y(), 0.7) << dd.leeward().transpose();
    // A point moved off mid-sail along the surface normal to leeward is at +δ.
    const SailSurface s(d);
    const Vec3 p = s.at(0.5, 0.5);
    const Vec3 n = (s.at(0.51, 0.5) - s.at(0.49, 0.5)).cross(s.at(0.5, 0.51) - s.at(0.5, 0.49)).normalized();
    const Vec3 lee = n.dot(dd.leeward()) > 0 ? n : Vec3(-n);
    EXPECT_NEAR(dd.signedDistance(p + 0.1 * lee), 0.1, 1e-3);
    EXPECT_NEAR(dd.signedDistance(p - 0.1 * lee), -0.1, 1e-3);
  }
}

TEST(DesignCompare, DistanceStatistics) {
  std::vector<double> d;
  for (int i = 0; i <= 100; ++i) d.push_back((i - 50) * 0.001 + 0.002);  // −0.048 … 0.052
  std::shuffle(d.begin(), d.end(), std::mt19937_64(1));
  const DistanceStats s = distanceStats(d);
  EXPECT_EQ(s.count, 101u);
  EXPECT_NEAR(s.mean_m, 0.002, 1e-15);
  double sum2 = 0;
  for (double v : d) sum2 += v * v;
  EXPECT_NEAR(s.rms_m, std::sqrt(sum2 / 101), 1e-15);
  EXPECT_NEAR(s.max_abs_m, 0.052, 1e-15);
  EXPECT_NEAR(s.p5_m, -0.043, 1e-12);
  EXPECT_NEAR(s.p50_m, 0.002, 1e-12);
  EXPECT_NEAR(s.p95_m, 0.047, 1e-12);
  const DistanceStats one = distanceStats({-0.25});
  EXPECT_EQ(one.p5_m, -0.25);
  EXPECT_EQ(one.max_abs_m, 0.25);
}

// Analysing a generated design's mesh recovers the parameters it was generated
// from, at the clean-data tolerances of the analysis core: camber 0.1 %, draft
// 1 %, twist 0.1°, entry/exit 1°; the chord to 5 mm.
void expectKnownSections(const SailSurface& surface, const MeshSections& a) {
  ASSERT_EQ(a.sections.sections.size(), 3u);
  for (const Section& s : a.sections.sections) {
    SCOPED_TRACE("fraction " + std::to_string(s.fraction));
    const KnownSection k = surface.section(s.fraction);
    EXPECT_NEAR(s.value.chord_m, k.chord_m, 0.005);
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 0.1);
    EXPECT_NEAR(s.value.draft_pct, k.draft_pct, 1.0);
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 0.1);
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, 1.0);
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, 1.0);
  }
}

TEST(DesignCompare, GeneratedDesignsRecoverTheirSectionParameters) {
  // The default analysis resamples the mesh, so even the generator's default 80 × 40 mesh will do.
  for (SailType type : {SailType::Main, SailType::SquareTopMain, SailType::Jib, SailType::Gennaker}) {
    SCOPED_TRACE(sailTypeName(type));
    const SailDesign design = exampleDesign(type);
    const MeshSections a = analyzeMeshSections(generateSailMesh(design));
    EXPECT_TRUE(a.resampled);
    expectKnownSections(SailSurface(design), a);
    EXPECT_NEAR((a.outline.tack - SailSurface(design).tack()).norm(), 0, 0.01);
  }
}

TEST(DesignCompare, FineGeneratedMeshesRecoverTheirSectionParametersAsTheyAre) {
  // Without resampling the outline puts a regular grid's edges about one column
  // spacing out; at 400 × 300 that is ~1 cm, inside the clean tolerances.
  MeshSampling as_is;
  as_is.mode = "mesh";
  for (SailType type : {SailType::Main, SailType::SquareTopMain, SailType::Jib, SailType::Gennaker}) {
    SCOPED_TRACE(sailTypeName(type));
    const SailDesign design = exampleDesign(type);
    const MeshSections a = analyzeMeshSections(generateSailMesh(design, 400, 300), {}, {}, as_is);
    EXPECT_FALSE(a.resampled);
    const SailSurface surface(design);
    ASSERT_EQ(a.sections.sections.size(), 3u);
    for (const Section& s : a.sections.sections) {
      const KnownSection k = surface.section(s.fraction);
      EXPECT_NEAR(s.value.chord_m, k.chord_m, 0.02);
      EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 0.1);
      EXPECT_NEAR(s.value.draft_pct, k.draft_pct, 1.0);
      EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 0.1);
      EXPECT_NEAR(s.value.entry_deg, k.entry_deg, 1.0);
      EXPECT_NEAR(s.value.exit_deg, k.exit_deg, 1.0);
    }
  }
}

TEST(DesignCompare, BoundaryCountAndAreaUniformSampling) {
  // Two separate triangles, areas 0.5 and 1.5: two boundary loops of 3 edges.
  Mesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 0, 0), Vec3(8, 0, 0), Vec3(5, 1, 0)};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  const BoundaryCount b = countBoundary(m);
  EXPECT_EQ(b.edges, 6u);
  EXPECT_EQ(b.loops, 2u);
  const Mesh grid = gridMesh(4, [](double s, double t) { return Vec3(s, t, 0); });
  EXPECT_EQ(countBoundary(grid).edges, 16u);
  EXPECT_EQ(countBoundary(grid).loops, 1u);

  const Cloud c = sampleMesh(m, 40000, 7);
  ASSERT_EQ(c.size(), 40000u);
  size_t second = 0;
  for (const Vec3& p : c.points) {
    ASSERT_EQ(p.z(), 0.0);
    const bool in_first = p.x() >= 0 && p.y() >= 0 && p.x() + p.y() <= 1 + 1e-12;
    const bool in_second = p.x() >= 5 && p.y() >= 0 && (p.x() - 5) / 3 + p.y() <= 1 + 1e-12;
    ASSERT_TRUE(in_first || in_second) << p.transpose();
    second += in_second;
  }
  // Binomial: 75 % ± 0.22 % (1σ) in the larger triangle.
  EXPECT_NEAR(static_cast<double>(second) / 40000.0, 0.75, 0.01);
  EXPECT_EQ(sampleMesh(m, 10, 3).points, sampleMesh(m, 10, 3).points);  // fixed seed, same samples
}

TEST(DesignCompare, DeeperFlyingShapeShowsAsPositiveDistancesAndCamberDeltas) {
  const SailDesign design = exampleDesign(SailType::Main);
  SailDesign flying = design;
  for (ProfileStation& st : flying.stations) st.camber_pct += 2.0;  // eased: 2 % deeper everywhere
  const Mesh design_mesh = generateSailMesh(design, 160, 100);
  const Mesh flying_mesh = generateSailMesh(flying, 160, 100);
  const MeshSections ds = analyzeMeshSections(design_mesh), fs = analyzeMeshSections(flying_mesh);
  ScanSimulation sim;
  sim.points = 20000;
  const Cloud cloud = sampleSail(flying, sim);
  const DesignComparison c = compareWithDesign(design_mesh, ds.sections, cloud.points, fs.sections);
  ASSERT_EQ(c.distance_m.size(), cloud.size());
  ASSERT_EQ(c.sections.size(), 3u);
  for (const SectionDelta& s : c.sections) {
    EXPECT_NEAR(s.delta.camber_pct, 2.0, 0.2);
    EXPECT_NEAR(s.delta.camber_pct, s.flying.camber_pct - s.design.camber_pct, 1e-12);
    EXPECT_NEAR(s.delta.twist_deg, 0.0, 0.2);
  }
  // The deeper sail stands to leeward of its design: up to 2 % of the longest chord.
  EXPECT_GT(c.stats.mean_m, 0.0);
  EXPECT_GT(c.stats.p50_m, 0.0);
  EXPECT_GE(c.stats.p5_m, -1e-3);
  EXPECT_LT(c.stats.max_abs_m, 0.02 * 3.7);
  EXPECT_GT(c.leeward.y(), 0.7);
}

TEST(DesignCompare, ASectionUnmeasuredOnOneSideHasNoDeltaAndTwistRelStartsAtTheLowestShared) {
  // Asked for 0.25, 0.5 and 0.75 on both; the flying 0.25 was not measured.
  auto section = [](double f, double camber, double twist, double twist_rel) {
    Section s;
    s.fraction = f;
    s.value.camber_pct = camber;
    s.value.twist_deg = twist;
    s.value.twist_rel_deg = twist_rel;
    return s;
  };
  SectionAnalysis design, flying;
  design.sections = {section(0.25, 10, 20, 0), section(0.5, 11, 24, 4), section(0.75, 12, 30, 10)};
  flying.sections = {section(0.5, 12, 27, 0), section(0.75, 14, 35, 8)};
  flying.unmeasured = {{0.25, "leaves 14 % of the chord at the leech uncovered (at most 10 %)"}};
  const std::vector<SectionDelta> d = sectionDeltas(design, flying);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_DOUBLE_EQ(d[0].fraction, 0.5);
  EXPECT_DOUBLE_EQ(d[1].fraction, 0.75);
  EXPECT_DOUBLE_EQ(d[0].delta.camber_pct, 1);
  EXPECT_DOUBLE_EQ(d[1].delta.camber_pct, 2);
  EXPECT_DOUBLE_EQ(d[1].delta.twist_deg, 5);
  // From 0.5 on both sides: the design twists 6° from there, the flying sail 8°.
  EXPECT_DOUBLE_EQ(d[0].design.twist_rel_deg, 0);
  EXPECT_DOUBLE_EQ(d[1].design.twist_rel_deg, 6);
  EXPECT_DOUBLE_EQ(d[1].flying.twist_rel_deg, 8);
  EXPECT_DOUBLE_EQ(d[1].delta.twist_rel_deg, 2);
  // Unmeasured on the design side instead: the same pairs.
  std::swap(design.sections, flying.sections);
  std::swap(design.unmeasured, flying.unmeasured);
  EXPECT_EQ(sectionDeltas(design, flying).size(), 2u);
}

TEST(DesignCompare, ThrowsOnBadInput) {
  expectInvalidInput([] { DesignDistance d{Mesh{}}; }, {"[DesignDistance]", "no triangles"});
  Mesh bad;
  bad.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  bad.triangles = {{0, 1, 2}};
  expectInvalidInput([&] { DesignDistance d{bad}; }, {"[DesignDistance]", "index 2"});
  bad.vertices.push_back(Vec3(2, 0, 0));  // collinear: zero area
  expectInvalidInput([&] { DesignDistance d{bad}; }, {"[DesignDistance]", "zero area"});
  expectInvalidInput([] { distanceStats({}); }, {"[distanceStats]"});

  SectionAnalysis a, b;
  a.sections.resize(2);
  a.sections[0].fraction = 0.25;
  a.sections[1].fraction = 0.5;
  b.sections.resize(2);
  b.sections[0].fraction = 0.25;
  b.sections[1].fraction = 0.75;
  expectInvalidInput([&] { sectionDeltas(a, b); }, {"[sectionDeltas]", "0.75"});
  b.sections.resize(1);
  expectInvalidInput([&] { sectionDeltas(a, b); }, {"[sectionDeltas]"});
  // Asked for different fractions, one of them unmeasured: still not the same sections.
  b.unmeasured = {{0.75, "crosses a hole"}};
  expectInvalidInput([&] { sectionDeltas(a, b); }, {"[sectionDeltas]", "0.75"});
  const Mesh tri = gridMesh(1, [](double s, double t) { return Vec3(s, t, 0); });
  expectInvalidInput([&] { sampleMesh(Mesh{}, 10); }, {"[sampleMesh]", "no triangles"});
  expectInvalidInput([&] { sampleMesh(tri, 0); }, {"[sampleMesh]", "points"});
  expectInvalidInput([&] { sampleMesh(bad, 10); }, {"[sampleMesh]", "zero area"});
  MeshSampling odd;
  odd.mode = "guess";
  expectInvalidInput([&] { analyzeMeshSections(tri, {}, {}, odd); }, {"[analyzeMeshSections]", "guess"});
  expectInvalidInput([&] { compareWithDesign(tri, a, {}, a); }, {"[compareWithDesign]", "no flying points"});
}

}  // namespace
}  // namespace sailshape
