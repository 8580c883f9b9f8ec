#pragma once
// Where the scanner stood, from a plain cloud's own sampling (a cloud exported
// without its scan angles or viewpoint).
//
// A unit on a turntable samples on a regular angular grid: scan lines a fixed
// angle apart in azimuth about the vertical shaft, beams a fixed angle apart
// along each line. A patch of surface at range r, seen at incidence θ and at
// elevation φ above the unit's horizontal, then holds
//     ρ = cos θ / (Ω · r² · cos φ)   samples per m²,
// Ω the grid's solid angle per beam at the horizon (sr). That is one model of
// the whole cloud with four unknowns (the position v and Ω): the density falls
// with range and with obliquity about v, and nowhere else. It is fitted to
// every patch's measured density in log space by robust least squares, from
// many starting positions (the model is not convex). An evenly sampled cloud
// fits every far position about as well: its σ is then as large as the
// distances, and no position is returned.
//
// A curved surface's density about v and about v's mirror image through the
// surface nearly agree: incidence and range, what the outline's coverage reads,
// agree too, but which side is which may not be known (`mirror_ambiguous`).
#include <optional>
#include <string>

#include "analysis/core/cloud.hpp"

namespace sailshape {

struct ViewpointEstimate {
  Vec3 position = Vec3::Zero();  // m, the cloud's frame
  Vec3 sigma_m = Vec3::Zero();   // 1σ per axis, m, from the fit's covariance
  double beam_solid_angle_sr = 0;  // Ω, sr per sample at the horizon
  double log_density_scatter = 0;  // robust σ of the patches' log-density residuals
  size_t patches = 0;              // patches the fit used
  // The mirror position fits within the scatter's noise as well: the side of the
  // surfaces the scanner stood on is not told by the density alone.
  bool mirror_ambiguous = false;
  double median_range_m = 0;  // median |p − position| over the patches
};

struct ViewpointEstimateParams {
  size_t max_patches = 4000;   // patches sampled over the cloud (evenly by index)
  // Patches whose samples lie closer than this many range-noise σ apart are left out
  // (their cells are shuffled by the noise, and read dense). sensor_sigma_m: SPEC §3.
  double sensor_sigma_m = 0.004;
  double min_spacing_sigmas = 2.0;
  size_t k_neighbours = 32;    // samples per patch: its plane, and the Voronoi cell its density is read from
  // The estimate is returned only when its 1σ (the norm of sigma_m) is at most
  // this share of the median range: coverage reads incidence from it, and a
  // position off by a quarter of the range tilts the rays by about 14° (the
  // outline then takes a boundary for a stop 2σ sooner: OutlineParams::
  // scanner_position_sigma_m).
  double max_relative_sigma = 0.25;
};

// The fitted scanner position, or nothing when the cloud's density does not tell
// it (evenly sampled, too few points, or a model that does not fit). Never throws
// on an odd cloud; `why` (when given) says what was missing.
std::optional<ViewpointEstimate> estimateViewpoint(const Cloud& cloud, const ViewpointEstimateParams& params = {},
                                                   std::string* why = nullptr);

}  // namespace sailshape
