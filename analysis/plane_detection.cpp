#include "analysis/plane_detection.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "analysis/errors.hpp"
#include "analysis/neighbours.hpp"
#include "analysis/normals.hpp"

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

}  // namespace

DetectedPlane fitPlane(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices) {
  if (indices.size() < 3)
    throw InvalidInput("[fitPlane] needs at least 3 points (got " + std::to_string(indices.size()) + ")");
  Vec3 c = Vec3::Zero();
  for (uint32_t i : indices) c += points[i];
  c /= static_cast<double>(indices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (uint32_t i : indices) {
    const Vec3 d = points[i] - c;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(indices.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  DetectedPlane plane;
  plane.normal = es.eigenvectors().col(0).normalized();
  plane.centroid = c;
  plane.offset_m = plane.normal.dot(c);
  plane.points = indices.size();
  plane.rms_m = std::sqrt(std::max(es.eigenvalues()(0), 0.0));
  plane.extent_m = 4 * std::sqrt(std::max(es.eigenvalues()(2), 0.0));
  plane.width_m = 4 * std::sqrt(std::max(es.eigenvalues()(1), 0.0));
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
  for (size_t c = 0; c < seg.clusters.size(); ++c) {
    progress("plane fitting", static_cast<double>(c) / static_cast<double>(seg.clusters.size()));
    const std::vector<uint32_t>& region = seg.clusters[c];
    std::vector<uint32_t> inliers = ransacInliers(cloud.points, region, p, rng);
    if (inliers.size() < 3 ||
        static_cast<double>(inliers.size()) < p.min_inlier_fraction * static_cast<double>(region.size())) {
      ++not_flat;
      continue;
    }
    // Tighten to 3 RMS of the fit (never wider than the RANSAC threshold): the
    // threshold band also catches the first millimetres of an adjoining face.
    double threshold = p.ransac_threshold_m;
    for (int pass = 0; pass < 3 && inliers.size() >= 3; ++pass) {
      inliers = refineInliers(cloud.points, inliers, threshold);
      if (inliers.size() >= 3) threshold = std::min(p.ransac_threshold_m, std::max(3 * fitPlane(cloud.points, inliers).rms_m, 1e-5));
    }
    if (inliers.size() < 3) {
      ++not_flat;
      continue;
    }
    DetectedPlane plane = fitPlane(cloud.points, inliers);
    if (plane.rms_m > p.max_rms_m) {
      ++not_flat;
      continue;
    }
    planes.push_back(std::move(plane));
  }
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
  const double cos_merge = std::cos(p.merge_angle_deg * M_PI / 180.0);
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
