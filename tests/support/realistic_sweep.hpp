#pragma once
// The one unit's sweep of a realistic scene (realistic_scene.hpp), as the product
// runs it and as the emulator's scanner answers (acquisition/scanner_emulator.cpp):
// scan lines in a vertical plane through the turntable's shaft, the plane turned
// about the shaft by β between lines (the turntable moves on while the mirror
// turns, so β grows along each line too); every beam measured by EmulatedSensor
// (range noise, systematic error, grazing dropouts, mixed pixels, out of range);
// every valid return placed by SPEC §2 with the unit's p, θ and pose.
#include <array>
#include <cstdint>
#include <vector>

#include "acquisition/scene.hpp"
#include "analysis/core/cloud.hpp"
#include "tests/support/realistic_scene.hpp"

namespace sailshape::realistic {

struct Scan {
  Cloud cloud;                  // boat frame; alpha_rad, beta_rad, intensity (RSSI) and viewpoint filled
  std::vector<int> object;      // per point: the scene object its beam's axis hit
  size_t sail_object = 0;       // index of the sail in the scene
  size_t beams = 0, lines = 0;
  // Beams that hit the sail, by what came back (ReturnStatus order: valid, no target, out of range,
  // grazing, edge loss): how much of the sail was out of reach.
  std::array<size_t, 5> sail_beams{};
  size_t sail_points() const { return sail_beams[0]; }
};

// Deterministic: the same config (and seed) gives the same cloud bit for bit, whatever `threads`.
Scan sweepScene(const Config& config, const Scene& scene, int threads = 1);

// The same cloud as another program would export it: points only (no angles, intensity, viewpoint).
Cloud plainXyz(const Cloud& cloud);

}  // namespace sailshape::realistic
