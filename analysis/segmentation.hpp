#pragma once
// Splitting a scene into surfaces and picking the sail (SPEC §4 step 3).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/cloud.hpp"
#include "analysis/neighbours.hpp"
#include "analysis/progress.hpp"

namespace sailshape {

struct Segmentation {
  std::vector<std::vector<uint32_t>> clusters;  // largest first
  std::vector<uint32_t> unassigned;
  std::vector<std::string> warnings;
};

struct EuclideanClusterParams {
  double tolerance_m = 0.05;  // points closer than this join the same cluster
  size_t min_points = 100;
  size_t max_points = 50'000'000;
};

Segmentation clusterEuclidean(const Cloud& cloud, const EuclideanClusterParams& params = {},
                              const Progress& progress = {});

// Region growing on normals and curvature: seeds in order of increasing
// curvature; a neighbour joins when its normal is within max_normal_angle_deg
// of the current point's, and grows further only when its curvature is below
// max_curvature. Regions outside [min_points, max_points] are left unassigned.
struct RegionGrowingParams {
  int k_neighbours = 30;
  double max_normal_angle_deg = 7.0;
  double max_curvature = 0.03;
  size_t min_points = 500;
  size_t max_points = 50'000'000;
};

Segmentation growRegions(const Cloud& cloud, const Normals& normals, const RegionGrowingParams& params = {},
                         const Progress& progress = {});
// Same, reusing a neighbour table with at least params.k_neighbours columns.
Segmentation growRegions(const Cloud& cloud, const Normals& normals, const NeighbourTable& table,
                         const RegionGrowingParams& params = {}, const Progress& progress = {});

// What the sail picker measured of one cluster.
struct ClusterInfo {
  size_t points = 0;
  Vec3 centroid = Vec3::Zero();
  Vec3 plane_normal = Vec3::UnitZ();
  double extent_m = 0;        // largest spread along the plane's principal axis (2 × 2σ)
  double plane_rms_m = 0;     // RMS distance to the best-fit plane: ~σ for walls, decimetres for sails
  double tilt_from_vertical_deg = 0;  // 0 for a vertical surface, 90 for deck or floor
  bool sail_like = false;
  std::string reason;         // why it is or is not sail-like
};

// Auto picks the largest cluster that is curved (plane_rms_m above
// min_depth_m and min_depth_ratio of its extent), large (extent_m >= min_extent_m)
// and not lying flat (tilt below max_tilt_deg). A seed point picks the cluster
// holding the point nearest to it; an index picks that cluster directly.
struct SailPickParams {
  std::string method = "auto";          // auto | seed | index
  std::vector<double> seed_point;       // [x, y, z] for "seed"
  int cluster_index = 0;                // for "index" (0 = largest)
  double min_depth_m = 0.02;
  double min_depth_ratio = 0.005;
  double min_extent_m = 0.3;
  double max_tilt_deg = 60.0;
};

struct SailPick {
  size_t cluster = 0;
  std::vector<ClusterInfo> candidates;  // one per cluster, same order
  std::vector<std::string> warnings;
};

// Adds to `cluster` the points outside every cluster (left unassigned, as
// edge points with one-sided neighbourhoods often are) when more than
// min_fraction of their neighbours (table rows, self excluded) are in it; repeated
// `passes` times. A mast beside the luff stays out: its points' neighbours are mast.
std::vector<uint32_t> addClusterFringe(const Segmentation& segmentation, size_t cluster, const NeighbourTable& table,
                                       double min_fraction = 0.5, int passes = 2);

// Throws AnalysisError when there is no cluster or nothing sail-like.
SailPick pickSailCluster(const Cloud& cloud, const Segmentation& segmentation, const SailPickParams& params = {});

}  // namespace sailshape
