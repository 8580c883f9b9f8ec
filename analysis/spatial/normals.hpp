#pragma once
// Normals and curvature from k-neighbourhoods (SPEC §4): the normal is the
// eigenvector of the smallest eigenvalue of the neighbourhood covariance, the
// curvature its surface variation λ0 / (λ0 + λ1 + λ2).
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape {

struct NormalParams {
  int k_neighbours = 20;
  // "viewpoint": towards the cloud's viewpoint (falls back to "propagate" when
  // the cloud has none); "propagate": consistent across each connected patch by
  // walking the neighbour graph; "none": as computed.
  std::string orientation = "viewpoint";
  // Refit each normal with neighbours far off the first plane down-weighted
  // (the curvature stays the plain one).
  bool robust = true;
};

struct NormalEstimation {
  Normals normals;
  std::string orientation;            // what was actually done
  size_t flipped = 0;                 // normals reversed by the orientation step
  std::vector<std::string> warnings;
};

NormalEstimation estimateNormals(const Cloud& cloud, const NormalParams& params = {},
                                 const Progress& progress = {});

// Same, reusing a neighbour table with at least params.k_neighbours columns.
NormalEstimation estimateNormals(const Cloud& cloud, const NeighbourTable& table,
                                 const NormalParams& params = {}, const Progress& progress = {});

}  // namespace sailshape
