#pragma once
// Outlier removal (SPEC §4 step 4).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape {

struct Cleaning {
  std::vector<uint32_t> kept;     // indices into the input cloud, ascending
  std::vector<uint32_t> removed;
  double threshold_m = 0;         // the distance limit that was applied
  std::vector<std::string> warnings;
};

// Removes points whose mean distance to their k neighbours exceeds
// mean + std_ratio · standard deviation of that distance over the cloud.
struct StatisticalOutlierParams {
  int k_neighbours = 20;
  double std_ratio = 5.0;
};
Cleaning removeStatisticalOutliers(const Cloud& cloud, const StatisticalOutlierParams& params = {},
                                   const Progress& progress = {});
// Same, reusing the cloud's neighbour table (nearestNeighbours) with more than
// params.k_neighbours columns.
Cleaning removeStatisticalOutliers(const Cloud& cloud, const NeighbourTable& table,
                                   const StatisticalOutlierParams& params = {}, const Progress& progress = {});

// Removes points with fewer than min_neighbours other points within radius_m.
// radius_m = 0 picks 4 × the median nearest-neighbour spacing.
struct RadiusOutlierParams {
  double radius_m = 0.0;
  int min_neighbours = 4;
};
Cleaning removeRadiusOutliers(const Cloud& cloud, const RadiusOutlierParams& params = {},
                              const Progress& progress = {});
// Same, reusing the cloud's neighbour table with more than params.min_neighbours columns.
Cleaning removeRadiusOutliers(const Cloud& cloud, const NeighbourTable& table, const RadiusOutlierParams& params = {},
                              const Progress& progress = {});

// Points the outlier filters removed only for being sparse (the narrow tip of a
// head, a far and thinly sampled edge) still lie on the surface the kept points
// describe. A removed point is readmitted when its nearest kept point is within
// max_gap_factor × the kept points' median spacing and it lies within
// max_offset_m (or 3x the neighbours' own RMS about it, where the surface curves
// within their reach) of the plane through its k nearest kept points; `passes` rounds,
// so a chain of tip points comes back one by one. Points off the surface
// (mixed pixels, spray, rigging) stay out.
struct ReadmitParams {
  int k_neighbours = 12;
  double max_offset_m = 0.0;     // must be > 0 here; in AnalysisParams 0 means 3 × sensor σ
  // The last sample of a narrow tip stands out alone: a wedge of angle θ sampled at
  // ρ points/m² stays empty for about 1/√(ρ·tan(θ/2)), 2.4 spacings at a 20° head
  // and 3.4 at 10°, and ten spacings take in about three times that (fewer leave a
  // head's last sample out, and the head low by centimetres).
  double max_gap_factor = 10.0;
  int passes = 4;
};
// `kept` indexes `cloud` (ascending); the result's kept/removed index `cloud` too.
Cleaning readmitSurfacePoints(const Cloud& cloud, const std::vector<uint32_t>& kept, const ReadmitParams& params = {});

}  // namespace sailshape
