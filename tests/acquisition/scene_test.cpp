// Scenes and the ray caster: known geometry, and the BVH against brute force.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>

#include "acquisition/ray_caster.hpp"
#include "acquisition/scene.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

using namespace sailshape;

namespace {

// Independent reference: every triangle tested, no hierarchy.
double bruteForce(const Scene& scene, const Vec3& o, const Vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const SceneObject& obj : scene.objects)
    for (const auto& t : obj.mesh.triangles) {
      const Vec3 a = obj.mesh.vertices[t[0]], b = obj.mesh.vertices[t[1]], c = obj.mesh.vertices[t[2]];
      const Vec3 n = (b - a).cross(c - a);
      const double den = n.dot(d);
      if (std::abs(den) < 1e-15) continue;
      const double s = n.dot(a - o) / den;
      if (s <= 1e-6 || s >= best) continue;
      const Vec3 p = o + s * d;
      if ((b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0)
        best = s;
    }
  return best;
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(Scene, BoxIsClosedWithOutwardNormals) {
  const Mesh box = makeBox(Vec3(0, 0, 0), Vec3(1, 2, 3));
  EXPECT_NEAR(meshArea(box), 2 * (1 * 2 + 2 * 3 + 1 * 3), 1e-12);
  const Vec3 centre(0.5, 1, 1.5);
  for (size_t t = 0; t < box.triangles.size(); ++t)
    EXPECT_GT(triangleNormal(box, t).dot(box.vertices[box.triangles[t][0]] - centre), 0) << "triangle " << t;
  EXPECT_THROW(makeBox(Vec3(0, 0, 0), Vec3(1, 0, 1)), InvalidInput);
}

TEST(Scene, CylinderAreaApproachesTheCircle) {
  const Mesh c = makeCylinder(Vec3(0, 0, 0), Vec3(0, 0, 2), 0.5, 3.0, 256);
  const double exact = 2 * M_PI * 0.5 * 3.0 + 2 * M_PI * 0.25;
  EXPECT_NEAR(meshArea(c), exact, exact * 1e-3);
  EXPECT_THROW(makeCylinder(Vec3::Zero(), Vec3::UnitZ(), 0.0, 1.0), InvalidInput);
  EXPECT_THROW(makeCylinder(Vec3::Zero(), Vec3::Zero(), 1.0, 1.0), InvalidInput);
  EXPECT_THROW(makeCylinder(Vec3::Zero(), Vec3::UnitZ(), 1.0, 1.0, 2), InvalidInput);
}

TEST(Scene, BuiltInTunnelHasChamberYachtAndBothSails) {
  const Scene s = builtInTunnelScene();
  std::vector<std::string> names;
  for (const SceneObject& o : s.objects) names.push_back(o.name);
  for (const char* want : {"floor", "ceiling", "wall_port", "hull", "mast", "boom", "main", "gennaker"})
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
  // The ceiling is 3.2 m above the deck-level origin; start away from the yacht.
  const RayCaster caster(s);
  const RayHit up = caster.cast(Vec3(3.0, 4.0, 0.5), Vec3::UnitZ());
  ASSERT_TRUE(up.hit);
  EXPECT_NEAR(up.distance_m, 3.2 - 0.5, 1e-9);
  EXPECT_EQ(s.objects[up.object].name, "ceiling");
}

TEST(RayCaster, KnownDistancesAndNormals) {
  Scene s;
  s.objects.push_back({"box", Material::Paint, makeBox(Vec3(4, -1, -1), Vec3(5, 1, 1))});
  const RayCaster caster(s);
  RayHit h = caster.cast(Vec3::Zero(), Vec3(2, 0, 0));  // non-unit direction
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 4.0, 1e-12);
  EXPECT_NEAR(h.normal.x(), -1.0, 1e-12);
  // 45° in XY: enters the x = 4 face at y = 4·tan... misses (y = 4 > 1); at 10° it hits x = 4.
  EXPECT_FALSE(caster.cast(Vec3::Zero(), Vec3(1, 1, 0)).hit);
  const double a = 10 * kRadPerDeg;
  h = caster.cast(Vec3::Zero(), Vec3(std::cos(a), std::sin(a), 0));
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance_m, 4.0 / std::cos(a), 1e-12);
  EXPECT_FALSE(caster.cast(Vec3::Zero(), Vec3(1, 0, 0), 1e-6, 3.9).hit) << "max distance honoured";
  EXPECT_FALSE(caster.cast(Vec3::Zero(), Vec3::Zero()).hit);
  Scene empty;
  EXPECT_THROW(RayCaster{empty}, InvalidInput);
}

TEST(RayCaster, MatchesBruteForceOnTheTunnelScene) {
  const Scene s = builtInTunnelScene();
  const RayCaster caster(s);
  EXPECT_GT(caster.nodeCount(), 1u);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int sail_hits = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 o(-2.5 + 0.3 * u(rng), -2.0 + 0.3 * u(rng), 1.0 + 0.3 * u(rng));
    // Aim at points around the sails so many rays meet curved cloth.
    const Vec3 target(0.3 * u(rng) - 0.2, 0.6 * u(rng), 1.4 + 1.2 * u(rng));
    const Vec3 d = (target - o).normalized();
    const RayHit h = caster.cast(o, d);
    const double ref = bruteForce(s, o, d);
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.distance_m, ref, 1e-9) << "ray " << i;
    if (s.objects[h.object].name == "main" || s.objects[h.object].name == "gennaker") ++sail_hits;
  }
  EXPECT_GT(sail_hits, 100);
}

// A bundle gives each ray what a cast of it alone gives: footprint-like bundles (rays a few milliradians
// apart, as a beam's rim), bundles of unrelated rays that part at the first node, axis-parallel rays
// (zero direction components) and a zero direction, which hits nothing.
TEST(RayCaster, ABundleGivesEachRayItsOwnCast) {
  const Scene s = builtInTunnelScene();
  const RayCaster caster(s);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  size_t hits = 0, bundles = 0;
  for (int i = 0; i < 300; ++i) {
    Vec3 o[RayCaster::kMaxBundle], d[RayCaster::kMaxBundle];
    const size_t n = 1 + i % RayCaster::kMaxBundle;
    const Vec3 o0(-2.5 + 0.3 * u(rng), -2.0 + 0.3 * u(rng), 1.0 + 0.3 * u(rng));
    const Vec3 d0 = Vec3(0.3 * u(rng) - 0.2, 0.6 * u(rng), 1.4 + 1.2 * u(rng)) - o0;
    for (size_t r = 0; r < n; ++r) {
      if (i % 3 == 2) {  // unrelated rays from anywhere in the chamber
        o[r] = Vec3(3 * u(rng), 3 * u(rng), 1.5 + u(rng));
        d[r] = Vec3(u(rng), u(rng), u(rng));
      } else {  // a footprint: 7 mm and 2.5 mrad about the axis
        o[r] = o0 + 0.007 * Vec3(u(rng), u(rng), u(rng));
        d[r] = d0.normalized() + 0.0025 * Vec3(u(rng), u(rng), u(rng));
      }
    }
    if (i == 5) d[1] = Vec3(0, 0, 1);      // parallel to two slab pairs
    if (i == 13) d[2] = Vec3(1, 0, 0);
    if (i == 21) d[3] = Vec3::Zero();      // no direction: no hit
    RayHit out[RayCaster::kMaxBundle];
    caster.castBundle(o, d, n, out);
    ++bundles;
    for (size_t r = 0; r < n; ++r) {
      const RayHit one = caster.cast(o[r], d[r]);
      ASSERT_EQ(out[r].hit, one.hit) << "bundle " << i << " ray " << r;
      if (!one.hit) continue;
      ++hits;
      EXPECT_EQ(out[r].distance_m, one.distance_m) << "bundle " << i << " ray " << r;
      EXPECT_EQ(out[r].object, one.object) << "bundle " << i << " ray " << r;
      EXPECT_NEAR(out[r].normal.dot(one.normal), 1.0, 1e-12);
    }
  }
  EXPECT_GT(hits, 1000u) << "over " << bundles << " bundles";
  Vec3 o[RayCaster::kMaxBundle + 1], d[RayCaster::kMaxBundle + 1];
  RayHit out[RayCaster::kMaxBundle + 1];
  EXPECT_THROW(caster.castBundle(o, d, RayCaster::kMaxBundle + 1, out), InvalidInput);
}

TEST(SceneJson, ObjectsAndPresets) {
  const Scene s = parseSceneJson(R"({"name": "bench", "objects": [
      {"type": "box", "name": "cube", "material": "light_grey", "min": [1, 1, 0], "max": [1.5, 1.5, 0.5]},
      {"type": "quad", "corners": [[5, -2, -1], [5, 2, -1], [5, 2, 3], [5, -2, 3]], "material": "cloth"},
      {"type": "cylinder", "base": [0, 3, 0], "axis": [0, 0, 1], "radius_m": 0.2, "length_m": 2},
      {"type": "chamber", "min": [-9, -9, -1], "max": [9, 9, 4]},
      {"type": "sail", "sail_type": "main", "scale": 0.5, "rows": 10, "columns": 6,
       "stations": [{"fraction": 0, "camber_pct": 12}, {"fraction": 1, "twist_deg": 20}]}]})");
  EXPECT_EQ(s.name, "bench");
  ASSERT_EQ(s.objects.size(), 3u + 6u + 1u);
  EXPECT_EQ(s.objects[0].material, Material::LightGrey);
  EXPECT_EQ(s.objects[1].material, Material::Cloth);
  EXPECT_EQ(s.objects.back().material, Material::Cloth);
  const SailDesign d = exampleDesign(SailType::Main);
  EXPECT_GT(meshArea(s.objects.back().mesh), 0.25 * 0.5 * d.luff_m * d.foot_m * 0.8);
  const Scene t = parseSceneJson(R"({"preset": "tunnel"})");
  EXPECT_EQ(t.objects.size(), builtInTunnelScene().objects.size());
  const Scene deck = parseSceneJson(R"({"preset": "deck"})");
  EXPECT_EQ(deck.objects.size(), builtInDeckScene().objects.size());
}

TEST(SceneJson, MeshFileRelativeToTheSceneFile) {
  const std::string obj = writeTemp("scene_test_tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string scene = writeTemp("scene_test.json", R"({"objects": [{"type": "mesh", "file": "scene_test_tri.obj"}]})");
  const Scene s = readSceneFile(scene);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].mesh.triangles.size(), 1u);
}

TEST(SceneJson, BadInputNamesTheProblem) {
  EXPECT_THROW(parseSceneJson("{not json"), FileError);
  EXPECT_THROW(parseSceneJson("[]"), FileError);
  EXPECT_THROW(parseSceneJson(R"({"objects": []})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"preset": "moon"})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"colour": 1, "preset": "tunnel"})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "torus"}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"name": "x"}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "box", "min": [0, 0], "max": [1, 1, 1]}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "box", "max": [1, 1, 1]}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "size": 2}]})"),
               InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "gold"}]})"),
               InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "quad", "corners": [[0,0,0]]}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "cylinder", "base": [0,0,0], "axis": [0,0,1], "radius_m": "x", "length_m": 1}]})"),
               InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "sail"}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "sail", "sail_type": "kite"}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "sail", "sail_type": "main", "luff_m": -1}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "sail", "sail_type": "main", "rows": 1}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "sail", "sail_type": "main", "stations": [{"camber_pct": 5}]}]})"),
               InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "mesh"}]})"), InvalidInput);
  EXPECT_THROW(parseSceneJson(R"({"objects": [{"type": "mesh", "file": "/nonexistent/x.obj"}]})"), FileError);
  EXPECT_THROW(readSceneFile("/nonexistent/scene.json"), FileError);
  EXPECT_THROW(parseMaterial("gold"), InvalidInput);
  EXPECT_EQ(parseMaterial(materialName(Material::DarkGrey)), Material::DarkGrey);
}
