#include "analysis/segmentation/plane_detection.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/core/fit.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/normals.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

void checkParams(const Cloud& cloud, const PlaneDetectionParams& p) {
  auto bad = [](const std::string& what) { throw InvalidInput("[detectPlanes] " + what); };
  if (p.normal_k < 3) bad("normal_k must be >= 3 (got " + std::to_string(p.normal_k) + ")");
  if (!(p.ransac_threshold_m > 0)) bad("ransac_threshold_m must be > 0 (got " + std::to_string(p.ransac_threshold_m) + ")");
  if (p.ransac_iterations < 1) bad("ransac_iterations must be >= 1 (got " + std::to_string(p.ransac_iterations) + ")");
  if (!(p.min_inlier_fraction > 0 && p.min_inlier_fraction <= 1))
    bad("min_inlier_fraction must be in (0, 1] (got " + std::to_string(p.min_inlier_fraction) + ")");
  if (!(p.max_rms_m > 0)) bad("max_rms_m must be > 0 (got " + std::to_string(p.max_rms_m) + ")");
  if (!(p.max_piece_rms_m > 0)) bad("max_piece_rms_m must be > 0 (got " + std::to_string(p.max_piece_rms_m) + ")");
  if (!(p.max_bow_m > 0)) bad("max_bow_m must be > 0 (got " + std::to_string(p.max_bow_m) + ")");
  if (!(p.min_extent_m >= 0)) bad("min_extent_m must be >= 0 (got " + std::to_string(p.min_extent_m) + ")");
  if (p.max_planes < 1) bad("max_planes must be >= 1");
  if (cloud.size() < static_cast<size_t>(std::max(p.normal_k, p.region.k_neighbours)))
    bad("cloud has " + std::to_string(cloud.size()) + " points, fewer than the " +
        std::to_string(std::max(p.normal_k, p.region.k_neighbours)) + " neighbours needed");
}

// Best plane of 3-point samples: the one with most points within the threshold.
std::vector<uint32_t> ransacInliers(const std::vector<Vec3>& pts, const std::vector<uint32_t>& region,
                                    const PlaneDetectionParams& p, std::mt19937_64& rng) {
  std::uniform_int_distribution<size_t> pick(0, region.size() - 1);
  size_t best_count = 0;
  Vec3 best_n = Vec3::UnitZ();
  double best_d = 0;
  for (int it = 0; it < p.ransac_iterations; ++it) {
    const Vec3 &a = pts[region[pick(rng)]], &b = pts[region[pick(rng)]], &c = pts[region[pick(rng)]];
    Vec3 n = (b - a).cross(c - a);
    if (n.norm() < 1e-12) continue;
    n.normalize();
    const double d = n.dot(a);
    size_t count = 0;
    for (uint32_t i : region) count += std::abs(n.dot(pts[i]) - d) <= p.ransac_threshold_m;
    if (count > best_count) {
      best_count = count;
      best_n = n;
      best_d = d;
    }
  }
  std::vector<uint32_t> inliers;
  for (uint32_t i : region)
    if (std::abs(best_n.dot(pts[i]) - best_d) <= p.ransac_threshold_m) inliers.push_back(i);
  return inliers;
}

// Inliers of `region` within the threshold of its least-squares plane, refit once.
std::vector<uint32_t> refineInliers(const std::vector<Vec3>& pts, const std::vector<uint32_t>& candidates,
                                    double threshold) {
  const DetectedPlane plane = fitPlane(pts, candidates);
  std::vector<uint32_t> kept;
  for (uint32_t i : candidates)
    if (std::abs(plane.normal.dot(pts[i]) - plane.offset_m) <= threshold) kept.push_back(i);
  return kept;
}

// RANSAC inliers of `region`, then tightened to 3 RMS of their least-squares
// fit (never wider than the RANSAC threshold): the threshold band also catches
// the first millimetres of an adjoining face.
std::vector<uint32_t> fitInliers(const std::vector<Vec3>& pts, const std::vector<uint32_t>& region,
                                 const PlaneDetectionParams& p, std::mt19937_64& rng) {
  std::vector<uint32_t> inliers = ransacInliers(pts, region, p, rng);
  double threshold = p.ransac_threshold_m;
  for (int pass = 0; pass < 3 && inliers.size() >= 3; ++pass) {
    inliers = refineInliers(pts, inliers, threshold);
    if (inliers.size() >= 3) threshold = std::min(p.ransac_threshold_m, std::max(3 * fitPlane(pts, inliers).rms_m, 1e-5));
  }
  return inliers;
}

// RMS over `indices` of the quadric w = a·u² + b·uv + c·v² + d·u + e·v + f
// fitted to their distances w from `plane` (u, v in the plane): how far the
// surface bows away from flat, apart from the noise. A few tenths of a
// millimetre for a face of thousands of points; the sagitta's scale for a
// band cut from a curved sail.
double bowRms(const std::vector<Vec3>& pts, const std::vector<uint32_t>& indices, const DetectedPlane& plane) {
  const Vec3 u = plane.normal.unitOrthogonal(), v = plane.normal.cross(u);
  QuadraticHeightField field;
  for (uint32_t i : indices) {
    const Vec3 d = pts[i] - plane.centroid;
    field.add(u.dot(d), v.dot(d), plane.normal.dot(d));
  }
  field.solve();
  double sum2 = 0;
  for (uint32_t i : indices) {
    const Vec3 d = pts[i] - plane.centroid;
    const double bow = field.height(u.dot(d), v.dot(d));
    sum2 += bow * bow;
  }
  return std::sqrt(sum2 / static_cast<double>(indices.size()));
}

// `all` less `remove` (both index lists into one cloud); `mark` is all-zero
// scratch of the cloud's size and is left all-zero.
std::vector<uint32_t> without(const std::vector<uint32_t>& all, const std::vector<uint32_t>& remove,
                              std::vector<uint8_t>& mark) {
  for (uint32_t i : remove) mark[i] = 1;
  std::vector<uint32_t> rest;
  for (uint32_t i : all)
    if (!mark[i]) rest.push_back(i);
  for (uint32_t i : remove) mark[i] = 0;
  return rest;
}

// The parts of `points` connected through the k-nearest-neighbour graph
// (either direction) with at least `min_points` each. The scattered outliers
// a fitted plane leaves behind have their neighbours on that plane, so they
// fall apart into parts too small to keep; a second face stays whole.
std::vector<std::vector<uint32_t>> connectedParts(const std::vector<uint32_t>& points, const NeighbourTable& table,
                                                  size_t min_points, std::vector<uint8_t>& mark) {
  std::vector<std::vector<uint32_t>> parts;
  if (points.size() < min_points) return parts;
  std::unordered_map<uint32_t, uint32_t> slot;  // cloud index -> position in `points`
  slot.reserve(points.size());
  for (uint32_t s = 0; s < points.size(); ++s) {
    slot.emplace(points[s], s);
    mark[points[s]] = 1;
  }
  std::vector<uint32_t> parent(points.size());
  for (uint32_t s = 0; s < parent.size(); ++s) parent[s] = s;
  auto root = [&](uint32_t s) {
    while (parent[s] != s) s = parent[s] = parent[parent[s]];
    return s;
  };
  for (uint32_t s = 0; s < points.size(); ++s) {
    const uint32_t* row = table.row(points[s]);
    for (size_t j = 1; j < table.k; ++j) {
      if (!mark[row[j]]) continue;
      const uint32_t a = root(s), b = root(slot.at(row[j]));
      if (a != b) parent[a] = b;
    }
  }
  for (uint32_t i : points) mark[i] = 0;
  std::unordered_map<uint32_t, std::vector<uint32_t>> groups;
  for (uint32_t s = 0; s < points.size(); ++s) groups[root(s)].push_back(points[s]);
  for (auto& g : groups)
    if (g.second.size() >= min_points) parts.push_back(std::move(g.second));
  // Deterministic order whatever the hash map's.
  std::sort(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.front() < b.front(); });
  return parts;
}

}  // namespace

DetectedPlane fitPlane(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices) {
  if (indices.size() < 3)
    throw InvalidInput("[fitPlane] needs at least 3 points (got " + std::to_string(indices.size()) + ")");
  const PrincipalAxes pa = principalAxes(points, indices);
  DetectedPlane plane;
  plane.normal = pa.axes.col(0);
  plane.centroid = pa.mean;
  plane.offset_m = plane.normal.dot(pa.mean);
  plane.points = indices.size();
  plane.rms_m = std::sqrt(pa.variance[0]);
  plane.extent_m = 4 * std::sqrt(pa.variance[2]);
  plane.width_m = 4 * std::sqrt(pa.variance[1]);
  plane.indices = indices;
  return plane;
}

Vec3 intersectPlanes(const DetectedPlane& a, const DetectedPlane& b, const DetectedPlane& c, double min_det) {
  Eigen::Matrix3d m;
  m.row(0) = a.normal.transpose();
  m.row(1) = b.normal.transpose();
  m.row(2) = c.normal.transpose();
  const double det = m.determinant();
  if (std::abs(det) < min_det)
    throw AnalysisError("[intersectPlanes] the three planes' normals are nearly coplanar (|det| = " +
                        std::to_string(std::abs(det)) + " < " + std::to_string(min_det) +
                        "): they do not meet in one point");
  return m.partialPivLu().solve(Vec3(a.offset_m, b.offset_m, c.offset_m));
}

PlaneDetection detectPlanes(const Cloud& cloud, const PlaneDetectionParams& p, const Progress& progress) {
  checkParams(cloud, p);
  const size_t k = static_cast<size_t>(std::max(p.normal_k, p.region.k_neighbours));
  const NeighbourTable table = nearestNeighbours(cloud.points, k, progress);
  NormalParams np;
  np.k_neighbours = p.normal_k;
  np.orientation = "none";  // region growing compares lines; plane signs are set below
  np.robust = false;
  const NormalEstimation normals = estimateNormals(cloud, table, np, progress);
  const Segmentation seg = growRegions(cloud, normals.normals, table, p.region, progress);

  PlaneDetection result;
  result.regions = seg.clusters.size();
  std::mt19937_64 rng(p.seed);
  std::vector<DetectedPlane> planes;
  size_t not_flat = 0, too_small = 0;
  std::vector<uint8_t> mark(cloud.size(), 0);  // scratch for without() and connectedParts()
  // Planes of `region`: its dominant plane, then those of each connected rest.
  // A region may hold more than one plane: where the normals turn gradually
  // over an edge, region growing can cross it. `whole`: a region as region
  // growing proposed it, which may be a plane seen at a grazing angle; any
  // other piece must be as flat as the sensor's noise allows.
  auto peel = [&](std::vector<uint32_t> first_region, bool whole) {
    const size_t first_plane = planes.size();
    std::vector<std::vector<uint32_t>> pending;
    pending.push_back(std::move(first_region));
    while (!pending.empty()) {
      const std::vector<uint32_t> region = std::move(pending.back());
      pending.pop_back();
      const std::vector<uint32_t> inliers = fitInliers(cloud.points, region, p, rng);
      const bool as_grown = whole;  // only the first piece is the region itself
      whole = false;
      if (inliers.size() < 3) {
        not_flat += as_grown;
        continue;
      }
      DetectedPlane plane = fitPlane(cloud.points, inliers);
      // A band or patch of a curved sail is nearly as close to its plane as a
      // face with noise, but it bows.
      const bool dominant = as_grown && static_cast<double>(inliers.size()) >=
                                           p.min_inlier_fraction * static_cast<double>(region.size());
      const bool flat = (dominant ? plane.rms_m <= p.max_rms_m
                                  : inliers.size() >= p.region.min_points && plane.rms_m <= p.max_piece_rms_m) &&
                        bowRms(cloud.points, inliers, plane) <= p.max_bow_m;
      if (!flat) {
        not_flat += as_grown;
        continue;
      }
      if (!dominant) ++result.split_planes;
      planes.push_back(std::move(plane));
      for (std::vector<uint32_t>& part :
           connectedParts(without(region, inliers, mark), table, p.region.min_points, mark))
        pending.push_back(std::move(part));
    }
    // The first plane's threshold band reaches over the edge into the next
    // face (12 mm / sin of the angle between them from the edge); each point
    // belongs to the plane it lies closest to.
    if (planes.size() - first_plane > 1) {
      std::vector<std::vector<uint32_t>> members(planes.size() - first_plane);
      for (size_t a = first_plane; a < planes.size(); ++a)
        for (uint32_t i : planes[a].indices) {
          size_t best = first_plane;
          for (size_t b = first_plane + 1; b < planes.size(); ++b)
            if (std::abs(planes[b].normal.dot(cloud.points[i]) - planes[b].offset_m) <
                std::abs(planes[best].normal.dot(cloud.points[i]) - planes[best].offset_m))
              best = b;
          members[best - first_plane].push_back(i);
        }
      for (size_t a = first_plane; a < planes.size(); ++a)
        if (members[a - first_plane].size() >= 3) planes[a] = fitPlane(cloud.points, members[a - first_plane]);
    }
  };
  std::vector<uint8_t> in_region(cloud.size(), 0);
  for (size_t c = 0; c < seg.clusters.size(); ++c) {
    progress("plane fitting", static_cast<double>(c) / static_cast<double>(seg.clusters.size() + 1));
    for (uint32_t i : seg.clusters[c]) in_region[i] = 1;
    peel(seg.clusters[c], true);
  }
  // Points in no region: at high density a k-neighbourhood is so small that
  // the range noise alone makes the surface variation of a face seen head-on
  // exceed the region-growing curvature limit, so it seeds no region. The
  // same peeling finds such faces among the connected leftovers.
  std::vector<uint32_t> leftover;
  for (uint32_t i = 0; i < cloud.size(); ++i)
    if (!in_region[i]) leftover.push_back(i);
  for (std::vector<uint32_t>& part : connectedParts(leftover, table, p.region.min_points, mark))
    peel(std::move(part), false);
  progress("plane fitting", 1.0);

  // Orientation towards the scanner, so a wall seen by two units inside the
  // same chamber has the same sign in both clouds.
  const Vec3 eye = cloud.viewpoint.value_or(Vec3::Zero());
  auto orient = [&](DetectedPlane& pl) {
    if (pl.normal.dot(eye - pl.centroid) < 0) {
      pl.normal = -pl.normal;
      pl.offset_m = -pl.offset_m;
    }
  };
  for (DetectedPlane& pl : planes) orient(pl);

  // Merge pieces of one plane (a wall cut in two by a mast's shadow).
  std::sort(planes.begin(), planes.end(), [](const auto& a, const auto& b) { return a.points > b.points; });
  const double cos_merge = std::cos(p.merge_angle_deg * kRadPerDeg);
  std::vector<DetectedPlane> merged;
  for (DetectedPlane& pl : planes) {
    bool absorbed = false;
    for (DetectedPlane& m : merged) {
      if (m.normal.dot(pl.normal) < cos_merge) continue;
      if (std::abs(m.normal.dot(pl.centroid) - m.offset_m) > p.merge_distance_m) continue;
      std::vector<uint32_t> all = m.indices;
      all.insert(all.end(), pl.indices.begin(), pl.indices.end());
      m = fitPlane(cloud.points, all);
      orient(m);
      absorbed = true;
      break;
    }
    if (!absorbed) merged.push_back(std::move(pl));
  }
  for (DetectedPlane& pl : merged) {
    if (pl.extent_m < p.min_extent_m || pl.width_m < p.min_extent_m) {
      ++too_small;
      continue;
    }
    result.planes.push_back(std::move(pl));
  }
  std::sort(result.planes.begin(), result.planes.end(),
            [](const auto& a, const auto& b) { return a.points > b.points; });
  if (result.planes.size() > p.max_planes) {
    result.warnings.push_back("kept the " + std::to_string(p.max_planes) + " largest of " +
                              std::to_string(result.planes.size()) + " planes");
    result.planes.resize(p.max_planes);
  }
  if (not_flat)
    result.warnings.push_back(std::to_string(not_flat) + " of " + std::to_string(seg.clusters.size()) +
                              " regions were not flat enough to be planes");
  if (too_small)
    result.warnings.push_back(std::to_string(too_small) + " planes narrower than min_extent_m (" +
                              std::to_string(p.min_extent_m) + " m) were dropped");
  return result;
}

}  // namespace sailshape
