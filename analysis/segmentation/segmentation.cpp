#include "analysis/segmentation/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

void sortLargestFirst(Segmentation& s) {
  std::stable_sort(s.clusters.begin(), s.clusters.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
}

void checkRegionParams(const Cloud& cloud, const Normals& normals, const RegionGrowingParams& p) {
  if (p.k_neighbours < 3)
    throw InvalidInput("[growRegions] k_neighbours must be >= 3 (got " + std::to_string(p.k_neighbours) + ")");
  if (!(p.max_normal_angle_deg > 0 && p.max_normal_angle_deg <= 90))
    throw InvalidInput("[growRegions] max_normal_angle_deg must be in (0, 90] (got " +
                       std::to_string(p.max_normal_angle_deg) + ")");
  if (!(p.max_curvature > 0))
    throw InvalidInput("[growRegions] max_curvature must be > 0 (got " + std::to_string(p.max_curvature) + ")");
  if (p.min_points > p.max_points)
    throw InvalidInput("[growRegions] min_points (" + std::to_string(p.min_points) + ") exceeds max_points (" +
                       std::to_string(p.max_points) + ")");
  if (normals.normals.size() != cloud.size() || normals.curvature.size() != cloud.size())
    throw InvalidInput("[growRegions] " + std::to_string(normals.normals.size()) + " normals for " +
                       std::to_string(cloud.size()) + " points");
  if (cloud.size() < static_cast<size_t>(p.k_neighbours))
    throw InvalidInput("[growRegions] cloud has " + std::to_string(cloud.size()) +
                       " points, fewer than k_neighbours = " + std::to_string(p.k_neighbours));
}

}  // namespace

Segmentation clusterEuclidean(const Cloud& cloud, const EuclideanClusterParams& p, const Progress& progress) {
  if (!(p.tolerance_m > 0))
    throw InvalidInput("[clusterEuclidean] tolerance_m must be > 0 (got " + std::to_string(p.tolerance_m) + ")");
  if (p.min_points > p.max_points)
    throw InvalidInput("[clusterEuclidean] min_points exceeds max_points");
  Segmentation result;
  if (cloud.empty()) throw InvalidInput("[clusterEuclidean] empty cloud");
  KdTree tree(cloud.points);
  std::vector<char> seen(cloud.size(), 0);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  size_t processed = 0;
  for (size_t s = 0; s < cloud.size(); ++s) {
    if (seen[s]) continue;
    std::vector<uint32_t> cluster{static_cast<uint32_t>(s)};
    seen[s] = 1;
    for (size_t q = 0; q < cluster.size(); ++q) {
      tree.withinRadius(cloud.points[cluster[q]], p.tolerance_m, idx, d2);
      for (uint32_t j : idx)
        if (!seen[j]) {
          seen[j] = 1;
          cluster.push_back(j);
        }
    }
    processed += cluster.size();
    if (cluster.size() >= p.min_points && cluster.size() <= p.max_points)
      result.clusters.push_back(std::move(cluster));
    else
      result.unassigned.insert(result.unassigned.end(), cluster.begin(), cluster.end());
    progress("clustering", static_cast<double>(processed) / static_cast<double>(cloud.size()));
  }
  sortLargestFirst(result);
  if (result.clusters.empty())
    result.warnings.push_back("no cluster has between " + std::to_string(p.min_points) + " and " +
                              std::to_string(p.max_points) + " points");
  return result;
}

Segmentation growRegions(const Cloud& cloud, const Normals& normals, const RegionGrowingParams& p,
                         const Progress& progress) {
  checkRegionParams(cloud, normals, p);
  const NeighbourTable table = nearestNeighbours(cloud.points, static_cast<size_t>(p.k_neighbours), progress);
  return growRegions(cloud, normals, table, p, progress);
}

Segmentation growRegions(const Cloud& cloud, const Normals& normals, const NeighbourTable& table,
                         const RegionGrowingParams& p, const Progress& progress) {
  checkRegionParams(cloud, normals, p);
  const size_t k = static_cast<size_t>(p.k_neighbours);
  if (table.size() != cloud.size() || table.k < k)
    throw InvalidInput("[growRegions] neighbour table does not match the cloud or has fewer than k_neighbours columns");
  const size_t n = cloud.size();
  const double cos_max = std::cos(p.max_normal_angle_deg * kPi / 180.0);

  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return normals.curvature[a] < normals.curvature[b]; });

  std::vector<uint32_t> label(n, kNone);
  Segmentation result;
  std::vector<uint32_t> region;
  std::deque<uint32_t> grow;
  size_t labelled = 0;
  uint32_t next_label = 0;
  for (uint32_t seed : order) {
    if (label[seed] != kNone) continue;
    region.clear();
    region.push_back(seed);
    label[seed] = next_label;
    if (normals.curvature[seed] < p.max_curvature) grow.push_back(seed);
    while (!grow.empty()) {
      const uint32_t cur = grow.front();
      grow.pop_front();
      const Vec3& nc = normals.normals[cur];
      const uint32_t* row = table.row(cur);
      for (size_t j = 1; j < k; ++j) {
        const uint32_t nb = row[j];
        if (label[nb] != kNone) continue;
        // Orientation may differ across a patch: compare lines, not vectors.
        if (std::abs(nc.dot(normals.normals[nb])) < cos_max) continue;
        label[nb] = next_label;
        region.push_back(nb);
        if (normals.curvature[nb] < p.max_curvature) grow.push_back(nb);
      }
    }
    labelled += region.size();
    ++next_label;
    if (region.size() >= p.min_points && region.size() <= p.max_points) {
      result.clusters.push_back(region);
    } else {
      result.unassigned.insert(result.unassigned.end(), region.begin(), region.end());
      if (region.size() > p.max_points)
        result.warnings.push_back("a region of " + std::to_string(region.size()) + " points exceeds max_points (" +
                                  std::to_string(p.max_points) + ") and was left unassigned");
    }
    if ((next_label & 255u) == 0) progress("region growing", static_cast<double>(labelled) / static_cast<double>(n));
  }
  progress("region growing", 1.0);
  sortLargestFirst(result);
  if (result.clusters.empty())
    result.warnings.push_back("no region has between " + std::to_string(p.min_points) + " and " +
                              std::to_string(p.max_points) + " points");
  return result;
}

std::vector<uint32_t> addClusterFringe(const Segmentation& seg, size_t cluster, const NeighbourTable& table,
                                       double min_fraction, int passes) {
  if (cluster >= seg.clusters.size())
    throw InvalidInput("[addClusterFringe] cluster " + std::to_string(cluster) + " out of range (" +
                       std::to_string(seg.clusters.size()) + " clusters)");
  if (table.k < 2) throw InvalidInput("[addClusterFringe] the neighbour table needs k >= 2");
  const size_t n = table.size();
  // 1: in the cluster, 2: in another cluster, 0: unassigned.
  std::vector<char> state(n, 0);
  for (size_t c = 0; c < seg.clusters.size(); ++c)
    for (uint32_t i : seg.clusters[c]) {
      if (i >= n) throw InvalidInput("[addClusterFringe] cluster index beyond the neighbour table");
      state[i] = c == cluster ? 1 : 2;
    }
  std::vector<uint32_t> members = seg.clusters[cluster];
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<uint32_t> added;
    for (uint32_t i : seg.unassigned) {
      if (i >= n || state[i] != 0) continue;
      const uint32_t* row = table.row(i);
      size_t in = 0;
      for (size_t j = 1; j < table.k; ++j) in += state[row[j]] == 1;
      if (static_cast<double>(in) > min_fraction * static_cast<double>(table.k - 1)) added.push_back(i);
    }
    if (added.empty()) break;
    for (uint32_t i : added) state[i] = 1;
    members.insert(members.end(), added.begin(), added.end());
  }
  std::sort(members.begin(), members.end());
  return members;
}

namespace {

// Points of each cluster within p.design_match_m of a design point, found in a
// voxel hash of the design points whose cells are design_match_m wide (a point's
// match lies in its own cell or a neighbour).
size_t designMatchedCluster(const Cloud& cloud, const Segmentation& seg, const std::vector<ClusterInfo>& info,
                            const SailPickParams& p) {
  if (p.design_points.empty()) throw InvalidInput("[pickSailCluster] method design needs the design's points");
  if (!(p.design_match_m > 0 && std::isfinite(p.design_match_m)))
    throw InvalidInput("[pickSailCluster] design_match_m must be > 0 (got " + std::to_string(p.design_match_m) + ")");
  const double cell = p.design_match_m, limit2 = cell * cell;
  std::unordered_map<int64_t, std::vector<uint32_t>> grid;
  for (uint32_t i = 0; i < p.design_points.size(); ++i) grid[voxelKey(p.design_points[i], cell)].push_back(i);
  auto near = [&](const Vec3& q) {
    const Eigen::Vector3i c = voxelOf(q, cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(voxelKey(Eigen::Vector3i(c + Eigen::Vector3i(dx, dy, dz))));
          if (it == grid.end()) continue;
          for (uint32_t j : it->second)
            if ((p.design_points[j] - q).squaredNorm() <= limit2) return true;
        }
    return false;
  };
  size_t best = 0, best_count = 0;
  bool best_sail_like = false;
  for (size_t c = 0; c < seg.clusters.size(); ++c) {
    size_t count = 0;
    for (uint32_t i : seg.clusters[c]) count += near(cloud.points[i]) ? 1 : 0;
    const bool sail_like = info[c].sail_like;
    if (count > 0 && ((sail_like && !best_sail_like) || (sail_like == best_sail_like && count > best_count))) {
      best = c;
      best_count = count;
      best_sail_like = sail_like;
    }
  }
  if (best_count == 0)
    throw AnalysisError("no part of the scan lies within " + std::to_string(static_cast<int>(std::lround(1000 * cell))) +
                        " mm of the sail's design (a plausible trim): the scan does not hold this sail");
  return best;
}

}  // namespace

SailPick pickSailCluster(const Cloud& cloud, const Segmentation& seg, const SailPickParams& p) {
  if (seg.clusters.empty()) throw AnalysisError("[pickSailCluster] segmentation found no cluster to pick a sail from");
  if (!(p.min_width_ratio >= 0 && p.min_width_ratio < 1))
    throw InvalidInput("[pickSailCluster] min_width_ratio must be in [0, 1) (got " + std::to_string(p.min_width_ratio) + ")");
  SailPick pick;
  for (const auto& cluster : seg.clusters) {
    ClusterInfo info;
    info.points = cluster.size();
    const PrincipalAxes pa = principalAxes(cloud.points, cluster);
    info.centroid = pa.mean;
    info.plane_normal = pa.axes.col(0);
    info.plane_rms_m = std::sqrt(pa.variance[0]);
    info.extent_m = 4.0 * std::sqrt(pa.variance[2]);
    info.width_m = 4.0 * std::sqrt(pa.variance[1]);
    // The spread off the plane, split into what a quadratic height field takes up (the
    // bend of a sail or a bowed panel) and what stays (noise and roughness).
    const HeightFieldSpread spread = quadraticHeightFieldSpread(cloud.points, cluster, pa);
    const double n = static_cast<double>(spread.points);
    info.bend_rms_m = std::sqrt((spread.plane_ss_m2 - spread.residual_ss_m2) / n);
    info.rough_rms_m = std::sqrt(spread.residual_ss_m2 / n);
    info.tilt_from_vertical_deg = std::asin(std::min(1.0, std::abs(info.plane_normal.z()))) * 180.0 / kPi;
    const double depth_needed = std::max(p.min_depth_m, p.min_depth_ratio * info.extent_m);
    using Shape = ClusterInfo::Shape;
    if (info.extent_m < p.min_extent_m) {
      info.shape = Shape::TooSmall;
      info.reason = "too small";
    } else if (info.width_m < p.min_width_ratio * info.extent_m) {
      info.shape = Shape::Narrow;  // before "flat": a boom seen from above lies flat too
      info.reason = "narrow (spar or pole)";
    } else if (info.tilt_from_vertical_deg > p.max_tilt_deg) {
      info.shape = Shape::Flat;
      info.reason = "lies flat (deck, floor or ceiling)";
    } else if (info.bend_rms_m < depth_needed) {
      info.shape = Shape::Planar;
      info.reason = "planar (wall or panel)";
    } else {
      info.shape = Shape::Curved;
      info.sail_like = true;
      info.reason = "curved surface";
    }
    pick.candidates.push_back(info);
  }

  if (p.method == "index") {
    if (p.cluster_index < 0 || static_cast<size_t>(p.cluster_index) >= seg.clusters.size())
      throw InvalidInput("[pickSailCluster] cluster_index " + std::to_string(p.cluster_index) + " out of range (" +
                         std::to_string(seg.clusters.size()) + " clusters)");
    pick.cluster = static_cast<size_t>(p.cluster_index);
  } else if (p.method == "seed") {
    if (p.seed_point.size() != 3)
      throw InvalidInput("[pickSailCluster] seed_point must be [x, y, z] (got " + std::to_string(p.seed_point.size()) +
                         " values)");
    const Vec3 seed(p.seed_point[0], p.seed_point[1], p.seed_point[2]);
    double best = std::numeric_limits<double>::infinity();
    for (size_t c = 0; c < seg.clusters.size(); ++c)
      for (uint32_t i : seg.clusters[c]) {
        const double d = (cloud.points[i] - seed).squaredNorm();
        if (d < best) {
          best = d;
          pick.cluster = c;
        }
      }
  } else if (p.method == "auto") {
    bool found = false;
    for (size_t c = 0; c < pick.candidates.size() && !found; ++c)
      if (pick.candidates[c].sail_like) {
        pick.cluster = c;
        found = true;
      }
    if (!found) {
      std::string why;
      for (size_t c = 0; c < std::min<size_t>(pick.candidates.size(), 4); ++c)
        why += (c ? "; " : "") + std::string("cluster ") + std::to_string(c) + " (" +
               std::to_string(pick.candidates[c].points) + " points): " + pick.candidates[c].reason;
      throw AnalysisError("[pickSailCluster] no sail-like cluster among " + std::to_string(seg.clusters.size()) +
                          " (" + why + ")");
    }
  } else if (p.method == "design") {
    pick.cluster = designMatchedCluster(cloud, seg, pick.candidates, p);
  } else {
    throw InvalidInput("[pickSailCluster] method must be auto, seed, index or design (got '" + p.method + "')");
  }
  if (!pick.candidates[pick.cluster].sail_like)
    pick.warnings.push_back("picked cluster " + std::to_string(pick.cluster) + " does not look like a sail (" +
                            pick.candidates[pick.cluster].reason + ")");
  return pick;
}

}  // namespace sailshape
