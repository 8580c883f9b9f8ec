#include "tests/support/realistic_sweep.hpp"

#include <cmath>
#include <random>
#include <thread>

#include "acquisition/sensor_model.hpp"
#include "acquisition/unit_config.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape::realistic {
namespace {

struct Line {
  std::vector<Vec3> points;
  std::vector<double> alpha, beta;
  std::vector<float> rssi;
  std::vector<int> object;
  std::array<size_t, 5> sail_beams{};
};

// Scan line k: beams α_i over the output range; β moves on by the line step over one mirror turn,
// so beam i fires at β_k + step · (α_i − α_first) / 360°. One random stream per line.
Line scanLine(const Config& c, const EmulatedSensor& sensor, const Eigen::Isometry3d& pose, size_t k, size_t beams,
              size_t sail_object) {
  const UnitSetup& u = c.unit;
  Line out;
  std::mt19937_64 rng(c.seed * 0x9E3779B97F4A7C15ULL + k + 1);
  const Eigen::Matrix3d R = pose.linear();
  const Vec3 T = pose.translation();
  const double beta_line = (u.beta_start_deg + u.line_step_deg * static_cast<double>(k)) * kRadPerDeg;
  for (size_t i = 0; i < beams; ++i) {
    const double alpha_deg = u.alpha_from_deg + u.resolution_deg * static_cast<double>(i);
    const double a = alpha_deg * kRadPerDeg;
    const double beta = beta_line + u.line_step_deg * kRadPerDeg * (alpha_deg - u.alpha_from_deg) / 360.0;
    const Vec3 origin(0, u.p_m * std::cos(beta + u.theta_rad), u.p_m * std::sin(beta + u.theta_rad));
    const Vec3 dir(std::cos(a), std::sin(a) * std::cos(beta), std::sin(a) * std::sin(beta));
    const BeamReturn b = sensor.measure(R * origin + T, R * dir, rng);
    if (b.object == static_cast<int>(sail_object)) ++out.sail_beams[static_cast<size_t>(b.status)];
    if (b.status != ReturnStatus::Valid) continue;
    // As the device reports it: whole millimetres.
    const double range = std::round(b.range_m * 1000.0) / 1000.0;
    out.points.push_back(pose * unitPoint(range, a, beta, u.p_m, u.theta_rad));
    out.alpha.push_back(a);
    out.beta.push_back(beta);
    out.rssi.push_back(b.rssi);
    out.object.push_back(b.object);
  }
  return out;
}

}  // namespace

Scan sweepScene(const Config& c, const Scene& scene, int threads) {
  Scan scan;
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].name == "sail") scan.sail_object = i;
  const EmulatedSensor sensor(scene, c.sensor);
  const UnitSetup& u = c.unit;
  const Eigen::Isometry3d pose = u.pose();
  const size_t beams = static_cast<size_t>(std::floor((u.alpha_to_deg - u.alpha_from_deg) / u.resolution_deg + 1e-9)) + 1;
  const size_t lines = static_cast<size_t>(std::floor(u.sweep_deg / u.line_step_deg + 1e-9)) + 1;
  scan.beams = beams * lines;
  scan.lines = lines;
  std::vector<Line> out(lines);
  const int workers = std::max(1, threads);
  std::vector<std::thread> pool;
  for (int w = 0; w < workers; ++w)
    pool.emplace_back([&, w] {
      for (size_t k = static_cast<size_t>(w); k < lines; k += static_cast<size_t>(workers))
        out[k] = scanLine(c, sensor, pose, k, beams, scan.sail_object);
    });
  for (std::thread& t : pool) t.join();
  Cloud& cloud = scan.cloud;
  for (const Line& l : out) {
    cloud.points.insert(cloud.points.end(), l.points.begin(), l.points.end());
    cloud.alpha_rad.insert(cloud.alpha_rad.end(), l.alpha.begin(), l.alpha.end());
    cloud.beta_rad.insert(cloud.beta_rad.end(), l.beta.begin(), l.beta.end());
    cloud.intensity.insert(cloud.intensity.end(), l.rssi.begin(), l.rssi.end());
    scan.object.insert(scan.object.end(), l.object.begin(), l.object.end());
    for (size_t s = 0; s < 5; ++s) scan.sail_beams[s] += l.sail_beams[s];
  }
  // The viewpoint and range sailshape's sweeps write (acquisition/sweep.cpp): the unit's position, its model's range.
  cloud.viewpoint = pose.translation();
  cloud.scanner_range_m = sensor.spec().max_range_m;
  return scan;
}

Cloud plainXyz(const Cloud& cloud) {
  Cloud out;
  out.points = cloud.points;
  return out;
}

}  // namespace sailshape::realistic
