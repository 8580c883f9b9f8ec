#pragma once
// A design and the same sail flying deeper and more twisted, scanned with gaps (issue 37's
// known answer): an interior hole over 20 % of the height and nothing above 88 % of it, as
// the sun and the range leave real scans. For tests/analysis/fit, the CLI's tests and the bench.
#include <array>
#include <cstdint>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/design/sail_generator.hpp"

namespace sailshape {

struct FitCaseOptions {
  SailType type = SailType::SquareTopMain;  // a wide head: its leech moves most with twist
  size_t points = 60'000;                   // on the whole flying sail, before the gaps
  double noise_sigma_m = 0.004;             // SPEC §3
  uint64_t seed = 1;
  bool scene = false;                       // mast, boom and deck too
  int rows = 80, columns = 40;              // the design mesh
  // The gaps, in fractions of the sail's height (h) and of the chord at that height (u).
  double hole_h_from = 0.40, hole_h_to = 0.60, hole_u_from = 0.2, hole_u_to = 0.8;
  double top_h = 0.88;
};

enum class FitRegion { Scanned, Hole, AboveTop };

struct FitCase {
  SailDesign design, flying;
  Mesh design_mesh;
  Cloud scan;                 // what the scanner kept (and the scene, when asked)
  std::vector<char> is_sail;  // per scan point
};

// The flying shape: 3 % deeper everywhere and 2° + 10°·f more twisted.
SailDesign deeperAndMoreTwisted(const SailDesign& design);

FitCase makeFitCase(const FitCaseOptions& options);

// Where a point of (or near) the flying sail lies against the scan's gaps.
FitRegion fitRegion(const SailSurface& flying, const Vec3& p, const FitCaseOptions& options);

// RMS and largest distance to the true flying surface of the vertices in each region
// (indexed by FitRegion: the region of the vertex's foot on the true surface). With
// `supported`, a vertex counts as scanned only where it is supported (one that stands beyond
// the flying sail's edge was not scanned, wherever its foot lies); with `sigma`, how many lie
// within 3σ.
struct RegionError {
  size_t count = 0;
  double rms_m = 0, max_m = 0;
  size_t within_3_sigma = 0;
};
std::array<RegionError, 3> regionErrors(const std::vector<Vec3>& vertices, const FitCase& c, const FitCaseOptions& o,
                                        const std::vector<char>* supported = nullptr,
                                        const std::vector<double>* sigma = nullptr);

}  // namespace sailshape
