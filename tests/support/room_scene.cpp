#include "tests/support/room_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

Cloud sweepUnit(const EmulatedSensor& sensor, const RigidTransform& pose, const RoomSceneParams& p, uint64_t seed) {
  const ScannerSpec& spec = sensor.spec();
  const double a_step = p.alpha_step_deg * kRadPerDeg;
  const double first = std::max(spec.first_angle_deg, p.alpha_first_deg);
  const double last = std::min(spec.last_angle_deg, p.alpha_last_deg);
  if (!(last > first)) throw InvalidInput("[makeRoomScene] the mirror window leaves no beam in the field of view");
  const double a0 = first * kRadPerDeg;
  const size_t count = static_cast<size_t>(std::floor((last - first) / p.alpha_step_deg)) + 1;
  const Eigen::Matrix3d rot = pose.linear();
  Cloud cloud;
  cloud.viewpoint = Vec3::Zero();
  const int lines = static_cast<int>(std::floor(p.beta_span_deg / p.beta_step_deg)) + 1;
  for (int k = 0; k < lines; ++k) {
    const double beta = (-p.beta_span_deg / 2 + k * p.beta_step_deg) * kRadPerDeg;
    // Unit frame: the mirror plane holds +X (α = 0) and (0, cos β, sin β) (α = 90°).
    const Vec3 ux = Vec3::UnitX(), uy(0, std::cos(beta), std::sin(beta));
    ScanLineRequest r;
    r.origin = pose.translation();
    r.axis_x = rot * ux;
    r.axis_y = rot * uy;
    r.start_rad = a0;
    r.step_rad = a_step;
    r.count = count;
    r.seed = seed * 1'000'003u + static_cast<uint64_t>(k);
    const std::vector<BeamReturn> line = sensor.scanLine(r);
    for (size_t i = 0; i < line.size(); ++i) {
      if (line[i].status != ReturnStatus::Valid || line[i].range_m > p.max_range_m) continue;
      const double alpha = a0 + a_step * static_cast<double>(i);
      cloud.points.push_back(line[i].range_m * (std::cos(alpha) * ux + std::sin(alpha) * uy));
      cloud.alpha_rad.push_back(alpha);
      cloud.beta_rad.push_back(beta);
      cloud.intensity.push_back(line[i].rssi);
    }
  }
  return cloud;
}

RoomScene makeRoomScene(const RoomSceneParams& p) {
  if (!(p.alpha_step_deg > 0) || !(p.beta_step_deg > 0) || !(p.beta_span_deg > 0))
    throw InvalidInput("[makeRoomScene] alpha_step_deg, beta_step_deg and beta_span_deg must be > 0");
  RoomScene out;
  out.scene.name = p.deck ? "deck" : "room";
  if (p.deck) {
    const Vec3 c = (p.room_min + p.room_max) / 2, h = p.room_max - p.room_min;
    const double z = p.room_min.z();
    out.scene.objects.push_back({"floor", Material::Paint,
                                 makeQuad(Vec3(c.x() - h.x(), c.y() - h.y(), z), Vec3(c.x() + h.x(), c.y() - h.y(), z),
                                          Vec3(c.x() + h.x(), c.y() + h.y(), z), Vec3(c.x() - h.x(), c.y() + h.y(), z))});
  } else {
    out.scene.objects = makeChamber(p.room_min, p.room_max);
  }
  if (p.cube_centre) {
    const double s = p.cube_size_m / 2;
    Mesh cube = makeBox(Vec3(-s, -s, -s), Vec3(s, s, s));
    const Eigen::Matrix3d rz = Eigen::AngleAxisd(p.cube_yaw_deg * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
    for (Vec3& v : cube.vertices) v = rz * v + *p.cube_centre;
    out.scene.objects.push_back({"cube", Material::LightGrey, cube});
  }
  if (p.mast_foot) out.scene.objects.push_back({"mast", Material::Metal, makeCylinder(*p.mast_foot, Vec3::UnitZ(), 0.05, 3.0, 24)});
  SensorModelParams sp;
  sp.model = p.model;
  sp.noise_scale = p.noise_scale;
  sp.systematic_fraction = p.reference_systematic_fraction;
  const EmulatedSensor ref_sensor(out.scene, sp);
  sp.systematic_fraction = p.moving_systematic_fraction;
  const EmulatedSensor mov_sensor(out.scene, sp);
  out.reference = sweepUnit(ref_sensor, p.reference_pose, p, p.seed);
  out.moving = sweepUnit(mov_sensor, p.moving_pose, p, p.seed + 7919);
  out.truth = p.reference_pose.inverse() * p.moving_pose;
  return out;
}

}  // namespace sailshape

namespace sailshape {

RandomCase randomRegistrationCase(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  auto uni = [&](double a, double b) { return a + (b - a) * U(rng); };
  RandomCase c;
  RoomSceneParams& p = c.params;
  p.seed = seed;
  p.alpha_step_deg = p.beta_step_deg = 0.5;
  p.deck = U(rng) < 0.2;
  const double ly = uni(2.6, 4.2);
  const double lz = U(rng) < 0.3 ? ly : uni(2.2, 3.2);  // a square cross-section: 90° turns fit the walls too
  const double lx = uni(4.5, 8.0);
  p.room_min = Vec3(-lx / 2, -ly / 2, 0);
  p.room_max = Vec3(lx / 2, ly / 2, lz);
  const bool cube = p.deck || U(rng) < 0.85;
  p.cube_size_m = uni(0.5, 0.6);
  if (cube) p.cube_centre = Vec3(uni(-lx / 2 + 0.8, lx / 2 - 0.8), uni(-ly / 2 + 0.7, ly / 2 - 0.7), p.cube_size_m / 2);
  else p.cube_centre.reset();
  p.cube_yaw_deg = uni(0, 90);
  if (p.deck) p.mast_foot = Vec3(uni(-1, 1), uni(-0.5, 0.5), 0);
  // Unit origins inside, clear of the walls, the cube and each other; any orientation.
  // Set up for the cube (most cases), both units stand before the same two
  // side faces of it, as a crew would place them to see one corner.
  const bool aimed = cube && U(rng) < 0.85;
  const double corner_yaw = (p.cube_yaw_deg + 45 + 90 * std::floor(uni(0, 4))) * kRadPerDeg;
  const Vec3 corner_dir(std::cos(corner_yaw), std::sin(corner_yaw), 0);
  auto origin = [&] {
    for (int attempt = 0;; ++attempt) {
      const Vec3 o(uni(-lx / 2 + 0.5, lx / 2 - 0.5), uni(-ly / 2 + 0.5, ly / 2 - 0.5), uni(0.8, lz - 0.5));
      if (p.cube_centre && (o - *p.cube_centre).norm() < 1.0) continue;
      if (aimed && attempt < 2000) {  // within ±30° of the corner's diagonal, so both faces face it
        const Vec3 d = (o - *p.cube_centre).cwiseProduct(Vec3(1, 1, 0)).normalized();
        if (d.dot(corner_dir) < std::cos(30 * kRadPerDeg)) continue;
      }
      if (p.mast_foot && std::hypot(o.x() - p.mast_foot->x(), o.y() - p.mast_foot->y()) < 0.5) continue;
      return o;
    }
  };
  auto rotation = [&] {
    const Eigen::Quaterniond q(uni(-1, 1), uni(-1, 1), uni(-1, 1), uni(-1, 1));
    return q.normalized().toRotationMatrix();
  };
  // Partial views: a mirror window of 180–270° and a sweep of 120–180°.
  const double window = uni(180, 270);
  p.alpha_first_deg = uni(-135, 135 - window);
  p.alpha_last_deg = p.alpha_first_deg + window;
  p.beta_span_deg = uni(120, 180);
  // Units set up for the cube look at it with the middle of their view, turned
  // any way about that line; the others are turned anyhow.
  const double mid = (p.alpha_first_deg + p.alpha_last_deg) / 2 * kRadPerDeg;
  const Vec3 middle_beam(std::cos(mid), std::sin(mid), 0);
  auto pose = [&](const Vec3& o) {
    RigidTransform t = RigidTransform::Identity();
    t.linear() = rotation();
    t.translation() = o;
    if (aimed) t.linear() = Eigen::Quaterniond::FromTwoVectors(t.linear() * middle_beam, *p.cube_centre - o).toRotationMatrix() * t.linear();
    return t;
  };
  p.reference_pose = pose(origin());
  Vec3 o;
  do o = origin();
  while ((o - p.reference_pose.translation()).norm() < 1.0);
  p.moving_pose = pose(o);
  p.noise_scale = U(rng) < 0.25 ? 0.0 : uni(0.5, 1.6);
  const bool systematic = U(rng) < 0.33;
  if (systematic) {
    p.reference_systematic_fraction = uni(0, 0.003);
    p.moving_systematic_fraction = uni(0, 0.003);
  }
  c.scene = makeRoomScene(p);
  const unsigned ref_faces = cubeFacesSeen(c.scene.reference, p.reference_pose, p, 200);
  const unsigned mov_faces = cubeFacesSeen(c.scene.moving, p.moving_pose, p, 200);
  // The bottom face (bit 4) stands on the floor: what lies there is floor.
  const int common = __builtin_popcount(ref_faces & mov_faces & ~(1u << 4));
  c.decidable = common >= 2;
  char buf[240];
  std::snprintf(buf, sizeof buf, "%s %.1f×%.1f×%.1f m, %s (%d faces seen by both), noise ×%.2f, range error %.2f/%.2f %%",
                p.deck ? "deck" : "room", lx, ly, lz, cube ? "cube" : "no cube", common, p.noise_scale,
                100 * p.reference_systematic_fraction, 100 * p.moving_systematic_fraction);
  c.label = buf;
  return c;
}

}  // namespace sailshape

namespace sailshape {

unsigned cubeFacesSeen(const Cloud& cloud, const RigidTransform& pose, const RoomSceneParams& p, size_t min_points) {
  if (!p.cube_centre) return 0;
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(p.cube_yaw_deg * kRadPerDeg, Vec3::UnitZ()).toRotationMatrix();
  const double h = p.cube_size_m / 2;
  size_t counts[6] = {0, 0, 0, 0, 0, 0};
  for (const Vec3& q : cloud.points) {
    const Vec3 local = rz.transpose() * (pose * q - *p.cube_centre);
    if (local.cwiseAbs().maxCoeff() > h + 0.01) continue;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side)
        if (std::abs(local[axis] - (side ? h : -h)) < 0.01) ++counts[2 * axis + side];
  }
  unsigned faces = 0;
  for (int f = 0; f < 6; ++f)
    if (counts[f] >= min_points) faces |= 1u << f;
  return faces;
}

}  // namespace sailshape

namespace sailshape {

RegistrationTolerance registrationTolerance(const RoomSceneParams& p) {
  const double sigma_ratio = p.noise_scale;  // materials' σ ≈ 4 mm at scale 1
  const double s = p.reference_systematic_fraction + p.moving_systematic_fraction;
  const double diagonal_m = (p.room_max - p.room_min).norm();
  return {0.01 + 0.04 * sigma_ratio + s / kRadPerDeg, 1e-4 + 0.0019 * sigma_ratio + s * diagonal_m};
}

}  // namespace sailshape
