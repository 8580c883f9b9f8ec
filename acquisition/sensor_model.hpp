#pragma once
// The emulated SICK LMS111/LMS511 measurement (SPEC §3): ray-cast range plus
// material noise, a systematic error growing linearly with distance, dropouts
// at grazing incidence and outside the model's range, mixed pixels where the
// beam footprint (exit diameter + divergence) straddles an edge, optional sun
// dazzle, and an 8-bit RSSI from incidence and material. Seeded: the same seed
// gives the same scan line bit for bit.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "acquisition/ray_caster.hpp"
#include "acquisition/scene.hpp"

namespace sailshape {

enum class ScannerModel { Lms111, Lms511 };

std::string scannerModelName(ScannerModel model);  // "lms111", "lms511"
ScannerModel parseScannerModel(const std::string& name);  // case-insensitive; throws InvalidInput

// Data-sheet facts per model (SPEC §3). Angles are the device's: 90° looks straight out.
struct ScannerSpec {
  double min_range_m, max_range_m;
  double first_angle_deg, last_angle_deg;  // field of view
  double beam_divergence_rad;               // full angle
  double exit_diameter_m;
  double default_frequency_hz, default_resolution_deg;
};
ScannerSpec scannerSpec(ScannerModel model);

struct OutlineParams;  // analysis/outline/sail_outline.hpp
struct Cloud;          // analysis/core/cloud.hpp
// The outline's scanner settings for a cloud this model measured: its footprint
// trims every edge (OutlineParams::beam_exit_diameter_m, beam_divergence_rad), and
// beyond its range the scan stops (scanner_max_range_m).
void useScannerBeam(OutlineParams& outline, ScannerModel model);
// The same for `cloud`: the range unless one is set, the beam unless the outline
// names one already or the cloud has no viewpoint to place the footprint from.
// Whether it set the beam.
bool useScannerBeamUnlessGiven(OutlineParams& outline, ScannerModel model, const Cloud& cloud);

// A beam's footprint as the emulator casts it: ray 0 is the axis from `origin`
// along the unit `direction`; rays 1-4 leave the exit window's rim (offsets
// rim_dirs[k] · exit radius) half the divergence out. Their directions are
// d + (divergence / 2) · rim_dirs[k], not normalised: a cast along them
// measures distance along the unit direction all the same.
struct BeamFootprint {
  Vec3 origins[5], directions[5];
  Vec3 rim_dirs[4];  // unit, across the axis: u, −u, v, −v
};
BeamFootprint beamFootprint(const ScannerSpec& spec, const Vec3& origin, const Vec3& direction);

// Per material (SPEC §3): 1σ random error, range bias, reflectivity in [0, 1].
struct MaterialResponse {
  double sigma_m, bias_m, reflectivity;
};
MaterialResponse materialResponse(Material material);

struct SensorModelParams {
  ScannerModel model = ScannerModel::Lms511;
  double noise_scale = 1.0;              // multiplies every material σ (0: noise-free ranges)
  double systematic_fraction = 0.002;    // range bias = fraction · r; SPEC §3: up to ≈ 0.3 % of range
  double dropout_start_deg = 70;         // incidence where returns start failing and σ rises
  double dropout_full_deg = 80;          // incidence beyond which nothing returns
  double grazing_noise_gain = 3.0;       // σ × (1 + gain·x), x from 0 to 1 across the dropout band
  bool mixed_pixels = true;
  double mixed_pixel_depth_m = 0.05;     // footprint rays further apart than this (beyond the incidence spread) straddle an edge
  std::optional<Vec3> sun_direction;     // unit vector towards the sun, scene frame
  double sun_cone_deg = 10;              // beams this close to the sun are dazzled
  double sun_noise_factor = 3.5;         // SPEC §3: σ up to ≈ 3.5× in direct sunlight
};

enum class ReturnStatus { Valid, NoTarget, OutOfRange, Grazing, EdgeLoss };
std::string returnStatusName(ReturnStatus status);

struct BeamReturn {
  ReturnStatus status = ReturnStatus::NoTarget;
  double range_m = 0;        // measured (0 unless Valid)
  double true_range_m = 0;   // noise-free distance to the first surface along the beam axis (0 if none)
  double incidence_deg = 0;  // at the axis hit
  uint8_t rssi = 0;          // 0 unless Valid
  int object = -1;           // scene object of the axis hit
  bool mixed = false;        // the footprint straddled an edge: range lies between surfaces
  bool dazzled = false;
};

// One scan line: beams at start + i·step (radians) in the scanner plane spanned by
// axis_x (angle 0) and axis_y (angle 90°), from `origin`; unit axes, scene frame.
struct ScanLineRequest {
  Vec3 origin = Vec3::Zero();
  Vec3 axis_x = Vec3::UnitX(), axis_y = Vec3::UnitY();
  double start_rad = 0, step_rad = 0;
  size_t count = 0;
  uint64_t seed = 1;
};

class EmulatedSensor {
 public:
  // Throws InvalidInput for out-of-range parameters (negative noise, dropout band inverted, ...).
  EmulatedSensor(const Scene& scene, const SensorModelParams& params);

  const SensorModelParams& params() const { return params_; }
  const ScannerSpec& spec() const { return spec_; }
  const RayCaster& caster() const { return caster_; }

  BeamReturn measure(const Vec3& origin, const Vec3& direction, std::mt19937_64& rng) const;
  // Throws InvalidInput when the angles leave the model's field of view or count is 0.
  std::vector<BeamReturn> scanLine(const ScanLineRequest& request) const;

 private:
  SensorModelParams params_;
  ScannerSpec spec_;
  RayCaster caster_;
  std::vector<Material> materials_;  // per scene object
};

}  // namespace sailshape
