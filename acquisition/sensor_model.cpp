#include "acquisition/sensor_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "analysis/core/cloud.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/outline/sail_outline.hpp"

namespace sailshape {

namespace {
}

std::string scannerModelName(ScannerModel model) { return model == ScannerModel::Lms111 ? "lms111" : "lms511"; }

ScannerModel parseScannerModel(const std::string& name) {
  std::string s = name;
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  if (s == "lms111") return ScannerModel::Lms111;
  if (s == "lms511") return ScannerModel::Lms511;
  throw InvalidInput("[parseScannerModel] unknown scanner model '" + name + "' (expected lms111 or lms511)");
}

ScannerSpec scannerSpec(ScannerModel model) {
  // The recordings: LMS111 at 50 Hz / 0.5° from -45°, LMS511 at 25 Hz / 0.1667° from -5°.
  if (model == ScannerModel::Lms111) return {0.5, 20.0, -45.0, 225.0, 0.015, 0.008, 50.0, 0.5};
  return {0.7, 80.0, -5.0, 185.0, 0.0047, 0.013, 25.0, 1.0 / 6.0};
}

void useScannerBeam(OutlineParams& outline, ScannerModel model) {
  const ScannerSpec spec = scannerSpec(model);
  outline.beam_exit_diameter_m = spec.exit_diameter_m;
  outline.beam_divergence_rad = spec.beam_divergence_rad;
  outline.scanner_max_range_m = spec.max_range_m;
}

bool useScannerBeamUnlessGiven(OutlineParams& outline, ScannerModel model, const Cloud& cloud) {
  if (outline.scanner_max_range_m == 0) outline.scanner_max_range_m = scannerSpec(model).max_range_m;
  if (outline.beamGiven() || !cloud.viewpoint) return false;
  useScannerBeam(outline, model);
  return true;
}

MaterialResponse materialResponse(Material material) {
  switch (material) {
    case Material::Cloth: return {0.0041, 0.0, 0.6};
    case Material::Tape: return {0.0033, 0.0, 1.0};
    case Material::LightGrey: return {0.0035, 0.0, 0.75};
    case Material::DarkGrey: return {0.0040, 0.015, 0.12};  // SPEC §3: ≈ 15 mm bias at 2 m
    case Material::Paint: return {0.0038, 0.0, 0.5};
    case Material::Metal: return {0.0040, 0.0, 0.4};
  }
  return {0.004, 0.0, 0.5};
}

std::string returnStatusName(ReturnStatus status) {
  switch (status) {
    case ReturnStatus::Valid: return "valid";
    case ReturnStatus::NoTarget: return "no target";
    case ReturnStatus::OutOfRange: return "out of range";
    case ReturnStatus::Grazing: return "grazing";
    case ReturnStatus::EdgeLoss: return "edge loss";
  }
  return "?";
}

EmulatedSensor::EmulatedSensor(const Scene& scene, const SensorModelParams& params)
    : params_(params), spec_(scannerSpec(params.model)), caster_(scene) {
  const auto bad = [](const std::string& what) { throw InvalidInput("[EmulatedSensor] " + what); };
  if (!(params.noise_scale >= 0)) bad("noise_scale must be >= 0 (got " + std::to_string(params.noise_scale) + ")");
  if (!(params.systematic_fraction >= 0 && params.systematic_fraction < 0.05))
    bad("systematic_fraction must be in [0, 0.05) (got " + std::to_string(params.systematic_fraction) + ")");
  if (!(params.dropout_start_deg > 0 && params.dropout_start_deg < params.dropout_full_deg &&
        params.dropout_full_deg <= 90))
    bad("need 0 < dropout_start_deg < dropout_full_deg <= 90 (got " + std::to_string(params.dropout_start_deg) +
        ", " + std::to_string(params.dropout_full_deg) + ")");
  if (!(params.mixed_pixel_depth_m > 0))
    bad("mixed_pixel_depth_m must be > 0 (got " + std::to_string(params.mixed_pixel_depth_m) + ")");
  if (params.sun_direction && !(params.sun_direction->norm() > 0)) bad("sun_direction must be non-zero");
  for (const SceneObject& o : scene.objects) materials_.push_back(o.material);
}

BeamFootprint beamFootprint(const ScannerSpec& spec, const Vec3& origin, const Vec3& direction) {
  BeamFootprint b;
  const Vec3 u = direction.unitOrthogonal(), v = direction.cross(u);
  const double half = 0.5 * spec.beam_divergence_rad, rim = 0.5 * spec.exit_diameter_m;
  b.rim_dirs[0] = u;
  b.rim_dirs[1] = -u;
  b.rim_dirs[2] = v;
  b.rim_dirs[3] = -v;
  b.origins[0] = origin;
  b.directions[0] = direction;
  for (int k = 0; k < 4; ++k) {
    b.origins[k + 1] = origin + rim * b.rim_dirs[k];
    b.directions[k + 1] = direction + half * b.rim_dirs[k];
  }
  return b;
}

BeamReturn EmulatedSensor::measure(const Vec3& origin, const Vec3& direction, std::mt19937_64& rng) const {
  BeamReturn out;
  const Vec3 d = direction.normalized();
  // Footprint: the axis ray plus four rays on the rim of the beam, weights 2:1:1:1:1, cast together
  // (they share one traversal of the scene).
  const BeamFootprint beam = beamFootprint(spec_, origin, d);
  const double half = 0.5 * spec_.beam_divergence_rad;
  RayHit hits[5];
  caster_.castBundle(beam.origins, beam.directions, params_.mixed_pixels ? 5 : 1, hits);
  const RayHit& axis = hits[0];
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  if (!axis.hit) return out;
  out.true_range_m = axis.distance_m;
  out.object = static_cast<int>(axis.object);
  const double cos_inc = std::clamp(-axis.normal.dot(d), 0.0, 1.0);
  out.incidence_deg = std::acos(cos_inc) / kRadPerDeg;

  double range = axis.distance_m;
  double weight = 2.0;
  if (params_.mixed_pixels) {
    const double spread_allowed =
        params_.mixed_pixel_depth_m + axis.distance_m * half * std::tan(std::min(out.incidence_deg, 85.0) * kRadPerDeg);
    double sum = 2.0 * axis.distance_m;
    bool straddles = false;
    for (int k = 0; k < 4; ++k) {
      const RayHit& h = hits[k + 1];
      if (!h.hit) {
        straddles = true;
        continue;
      }
      // The rim ray's range as the device would see it: along the axis direction.
      const double r = h.distance_m * beam.directions[k + 1].normalized().dot(d);
      if (h.object != axis.object || std::abs(r - axis.distance_m) > spread_allowed) straddles = true;
      sum += r;
      weight += 1.0;
    }
    if (straddles) {
      out.mixed = true;
      if (weight < 3.0) {
        out.status = ReturnStatus::EdgeLoss;  // less than half the energy came back
        return out;
      }
      range = sum / weight;
    } else {
      weight = 6.0;
    }
  } else {
    weight = 6.0;
  }

  if (out.true_range_m < spec_.min_range_m || out.true_range_m > spec_.max_range_m) {
    out.status = ReturnStatus::OutOfRange;
    return out;
  }
  const double x = std::clamp((out.incidence_deg - params_.dropout_start_deg) /
                                  (params_.dropout_full_deg - params_.dropout_start_deg),
                              0.0, 1.0);
  if (x >= 1.0 || (x > 0 && uniform(rng) < x)) {
    out.status = ReturnStatus::Grazing;
    return out;
  }
  const MaterialResponse m = materialResponse(materials_[axis.object]);
  double sigma = m.sigma_m * params_.noise_scale * (1.0 + params_.grazing_noise_gain * x);
  if (params_.sun_direction && d.dot(params_.sun_direction->normalized()) > std::cos(params_.sun_cone_deg * kRadPerDeg)) {
    sigma *= params_.sun_noise_factor;
    out.dazzled = true;
  }
  out.range_m = range * (1.0 + params_.systematic_fraction) + m.bias_m + sigma * gauss(rng);
  out.status = ReturnStatus::Valid;
  const double level = 254.0 * m.reflectivity * (0.35 + 0.65 * cos_inc) * (weight / 6.0);
  out.rssi = static_cast<uint8_t>(std::clamp(std::lround(level), 1L, 254L));
  return out;
}

std::vector<BeamReturn> EmulatedSensor::scanLine(const ScanLineRequest& req) const {
  if (req.count == 0) throw InvalidInput("[EmulatedSensor::scanLine] count must be > 0");
  const double first_deg = req.start_rad / kRadPerDeg;
  const double last_deg = (req.start_rad + req.step_rad * static_cast<double>(req.count - 1)) / kRadPerDeg;
  const double tol = 1e-6;
  if (std::min(first_deg, last_deg) < spec_.first_angle_deg - tol ||
      std::max(first_deg, last_deg) > spec_.last_angle_deg + tol)
    throw InvalidInput("[EmulatedSensor::scanLine] beams from " + std::to_string(first_deg) + "° to " +
                       std::to_string(last_deg) + "° leave the " + scannerModelName(params_.model) +
                       " field of view [" + std::to_string(spec_.first_angle_deg) + "°, " +
                       std::to_string(spec_.last_angle_deg) + "°]");
  std::mt19937_64 rng(req.seed);
  std::vector<BeamReturn> out(req.count);
  for (size_t i = 0; i < req.count; ++i) {
    const double a = req.start_rad + req.step_rad * static_cast<double>(i);
    out[i] = measure(req.origin, std::cos(a) * req.axis_x + std::sin(a) * req.axis_y, rng);
  }
  return out;
}

}  // namespace sailshape
