#pragma once
// Outlier removal (SPEC §4 step 4).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/cloud.hpp"
#include "analysis/progress.hpp"

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

// Removes points with fewer than min_neighbours other points within radius_m.
// radius_m = 0 picks 4 × the median nearest-neighbour spacing.
struct RadiusOutlierParams {
  double radius_m = 0.0;
  int min_neighbours = 4;
};
Cleaning removeRadiusOutliers(const Cloud& cloud, const RadiusOutlierParams& params = {},
                              const Progress& progress = {});

}  // namespace sailshape
