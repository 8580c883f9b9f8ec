#include "tests/support/tunnel_scene.hpp"

#include <cmath>
#include <random>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/design/sail_generator.hpp"

namespace sailshape {
namespace {

// Test section, tunnel frame (m): x along the flow, z up.
constexpr double kX0 = -3.0, kX1 = 3.0, kY0 = -1.8, kY1 = 1.8, kZ1 = 2.4;
const Vec3 kCubeCentre(1.9, 0.1, 0.3);
constexpr double kCubeSize = 0.6, kCubeYawDeg = 45.0;
const Vec3 kUnitA(-1.6, -1.1, 1.0), kUnitB(-1.4, 1.2, 1.1);
constexpr double kHalfOverlap = 0.5;  // each unit sees the chamber up to this far past the centreline

struct Rect {
  Vec3 corner, u, v, normal;  // points corner + a·u + b·v, a, b ∈ [0, 1]; normal towards the open side
  bool chamber;
};

std::vector<Rect> sceneRects() {
  std::vector<Rect> r;
  const double lx = kX1 - kX0, ly = kY1 - kY0;
  r.push_back({Vec3(kX0, kY0, 0), Vec3(lx, 0, 0), Vec3(0, ly, 0), Vec3::UnitZ(), true});       // floor
  r.push_back({Vec3(kX0, kY0, kZ1), Vec3(lx, 0, 0), Vec3(0, ly, 0), -Vec3::UnitZ(), true});    // ceiling
  r.push_back({Vec3(kX0, kY0, 0), Vec3(lx, 0, 0), Vec3(0, 0, kZ1), Vec3::UnitY(), true});      // starboard wall
  r.push_back({Vec3(kX0, kY1, 0), Vec3(lx, 0, 0), Vec3(0, 0, kZ1), -Vec3::UnitY(), true});     // port wall
  r.push_back({Vec3(kX1, kY0, 0), Vec3(0, ly, 0), Vec3(0, 0, kZ1), -Vec3::UnitX(), true});     // downstream screen
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(kCubeYawDeg * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  const double h = kCubeSize / 2;
  for (const Vec3& local : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
    const Vec3 n = rz * local, side = rz * Vec3(-local.y(), local.x(), 0);
    const Vec3 centre = kCubeCentre + h * n;
    r.push_back({centre - h * side - h * Vec3::UnitZ(), kCubeSize * side, kCubeSize * Vec3::UnitZ(), n, false});
  }
  const Vec3 ex = rz * Vec3::UnitX(), ey = rz * Vec3::UnitY();
  r.push_back({kCubeCentre + h * Vec3::UnitZ() - h * ex - h * ey, kCubeSize * ex, kCubeSize * ey, Vec3::UnitZ(), false});
  return r;
}

bool underCube(const Vec3& p) {
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(kCubeYawDeg * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 local = rz.transpose() * (p - kCubeCentre);
  return std::abs(local.x()) <= kCubeSize / 2 && std::abs(local.y()) <= kCubeSize / 2;
}

SailDesign modelSail(SailType type) {
  // The example designs at 1:5, as a wind-tunnel model.
  SailDesign d = exampleDesign(type);
  const double s = 0.2;
  d.luff_m *= s;
  d.leech_m *= s;
  d.foot_m *= s;
  d.head_width_m *= s;
  d.tack = d.tack * s + Vec3(0, 0, 0.2);
  return d;
}

// One unit's view, tunnel frame. `side` = −1 for the unit on the starboard (−Y) side.
Cloud scanUnit(const Vec3& unit, double side, SailType sail, const TunnelSceneParams& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> N(0, 1);
  Cloud cloud;
  for (const Rect& r : sceneRects()) {
    const double area = r.u.cross(r.v).norm();
    const double density = r.chamber ? p.chamber_density_per_m2 : p.cube_density_per_m2;
    const size_t n = static_cast<size_t>(std::llround(area * density));
    for (size_t i = 0; i < n; ++i) {
      const Vec3 q = r.corner + U(rng) * r.u + U(rng) * r.v;
      if (r.normal.dot(unit - q) <= 0) continue;  // the unit sees the face from behind
      if (r.chamber && side * q.y() < -kHalfOverlap) continue;  // the far half of the chamber is out of view
      if (r.chamber && q.z() == 0 && underCube(q)) continue;
      const double noise = p.noise_sigma_m > 0 ? p.noise_sigma_m * N(rng) : 0.0;
      cloud.points.push_back(q + noise * (q - unit).normalized());
    }
  }
  ScanSimulation sim;
  sim.points = p.sail_points;
  sim.noise_sigma_m = p.noise_sigma_m;
  sim.seed = rng();
  sim.viewpoint = unit;
  const Cloud sail_cloud = sampleSail(modelSail(sail), sim);
  cloud.points.insert(cloud.points.end(), sail_cloud.points.begin(), sail_cloud.points.end());
  cloud.viewpoint = unit;
  return cloud;
}

}  // namespace

TunnelScene makeTunnelScene(const TunnelSceneParams& p) {
  if (!(p.noise_sigma_m >= 0))
    throw InvalidInput("[makeTunnelScene] noise_sigma_m must be >= 0 (got " + std::to_string(p.noise_sigma_m) + ")");
  if (!(p.chamber_density_per_m2 > 0) || !(p.cube_density_per_m2 > 0))
    throw InvalidInput("[makeTunnelScene] densities must be > 0 (got " + std::to_string(p.chamber_density_per_m2) +
                       " and " + std::to_string(p.cube_density_per_m2) + " per m²)");
  if (p.sail_points == 0) throw InvalidInput("[makeTunnelScene] sail_points must be > 0");
  std::mt19937_64 rng(p.seed);
  TunnelScene scene;
  scene.truth = p.truth;
  scene.reference_pose = p.reference_pose;
  const RigidTransform to_a = p.reference_pose.inverse();
  const RigidTransform to_b = p.truth.inverse() * to_a;
  scene.reference = transformCloud(scanUnit(kUnitA, -1, SailType::Main, p, rng), to_a);
  scene.moving = transformCloud(scanUnit(kUnitB, +1, SailType::Jib, p, rng), to_b);

  scene.chamber.name = "wind-tunnel test section";
  scene.chamber.faces = {{"floor", Vec3::UnitZ(), 0.0},
                         {"ceiling", -Vec3::UnitZ(), -kZ1},
                         {"starboard wall", Vec3::UnitY(), kY0},
                         {"port wall", -Vec3::UnitY(), -kY1},
                         {"downstream screen", -Vec3::UnitX(), -kX1}};
  for (ReferenceFace& f : cubeFaces("cube", kCubeCentre, kCubeSize, kCubeYawDeg)) scene.chamber.faces.push_back(f);
  return scene;
}

}  // namespace sailshape
