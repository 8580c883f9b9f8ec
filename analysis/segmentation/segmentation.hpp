#pragma once
// Splitting a scene into surfaces and picking the sail (SPEC §4 step 3).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/progress.hpp"
#include "analysis/spatial/neighbours.hpp"

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
  double width_m = 0;         // the same across it, in the plane: a spar's diameter, a sail's chords
  double plane_rms_m = 0;     // RMS distance to the best-fit plane: ~σ for walls, decimetres for sails
  // Of that spread, what a smooth bend takes away (a quadratic height field over
  // the plane) and what stays: a sail's depth is the bend, a wall's is noise.
  double bend_rms_m = 0;
  double rough_rms_m = 0;
  double tilt_from_vertical_deg = 0;  // 0 for a vertical surface, 90 for deck or floor
  // What the picker made of it, in the order it asks: too small, narrow (a spar or
  // pole), lying flat (deck, floor), planar (wall, panel), or curved (sail-like).
  enum class Shape { TooSmall, Narrow, Flat, Planar, Curved };
  Shape shape = Shape::TooSmall;
  bool sail_like = false;
  std::string reason;         // why it is or is not sail-like
};

// Auto picks the largest cluster that is large (extent_m >= min_extent_m), not
// lying flat (tilt below max_tilt_deg), not a spar's narrow strip (width_m at least
// min_width_ratio of its extent) and bent (bend_rms_m at least min_depth_m and
// min_depth_ratio of its extent). The bend, not the plane's RMS, tells a sail from a
// wall: a wall's spread off its plane is noise that no smooth bend takes away, while
// a flat, tall mainsail spreads little more than a wall of its size would by noise
// and systematic error. A seed point picks the cluster holding the point nearest
// to it; an index picks that cluster directly. "design" picks the sail-like cluster with
// the most points within design_match_m of the design (any cluster when none is
// sail-like): another sail in the region lies farther from this one's design than
// any trim puts this one.
struct SailPickParams {
  std::string method = "auto";          // auto | seed | index
  std::vector<double> seed_point;       // [x, y, z] for "seed"
  int cluster_index = 0;                // for "index" (0 = largest)
  // 2σ of the sensor: the most a wall's systematic range error bends it (SPEC §3).
  double min_depth_m = 0.008;
  // A 10 m mainsail at 3 % camber bends about 2 cm (0.0018 of its 11.5 m extent).
  double min_depth_ratio = 0.0015;
  double min_extent_m = 0.3;
  double max_tilt_deg = 60.0;
  // Sails are at least a sixth as wide as tall (a blade jib); a mast is 1 %.
  double min_width_ratio = 0.08;
  // For "design": points on the sail's design surface (boat frame, metres, no farther
  // apart than design_match_m; set in code, not read from a params file) and how far
  // from it a sail flying at any plausible trim may lie (analysis/pipeline/sail_region.hpp).
  std::vector<Vec3> design_points;
  double design_match_m = 0;
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
