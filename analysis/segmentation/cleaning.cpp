#include "analysis/segmentation/cleaning.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "analysis/core/errors.hpp"
#include "analysis/segmentation/plane_detection.hpp"

namespace sailshape {

namespace {

void checkStatistical(const Cloud& cloud, const StatisticalOutlierParams& p) {
  if (p.k_neighbours < 1)
    throw InvalidInput("[removeStatisticalOutliers] k_neighbours must be >= 1 (got " +
                       std::to_string(p.k_neighbours) + ")");
  if (!(p.std_ratio > 0))
    throw InvalidInput("[removeStatisticalOutliers] std_ratio must be > 0 (got " + std::to_string(p.std_ratio) + ")");
  const size_t k = static_cast<size_t>(p.k_neighbours) + 1;
  if (cloud.size() < k)
    throw InvalidInput("[removeStatisticalOutliers] cloud has " + std::to_string(cloud.size()) +
                       " points, needs more than k_neighbours = " + std::to_string(p.k_neighbours));
}

void checkRadius(const Cloud& cloud, const RadiusOutlierParams& p) {
  if (p.radius_m < 0 || !std::isfinite(p.radius_m))
    throw InvalidInput("[removeRadiusOutliers] radius_m must be >= 0 (got " + std::to_string(p.radius_m) + ")");
  if (p.min_neighbours < 1)
    throw InvalidInput("[removeRadiusOutliers] min_neighbours must be >= 1 (got " +
                       std::to_string(p.min_neighbours) + ")");
  if (cloud.size() < 2) throw InvalidInput("[removeRadiusOutliers] cloud has fewer than 2 points");
}

void checkTable(const char* function, const Cloud& cloud, const NeighbourTable& table, size_t k) {
  if (table.size() != cloud.size() || table.k < k)
    throw InvalidInput(std::string("[") + function + "] neighbour table (" + std::to_string(table.size()) +
                       " rows, k = " + std::to_string(table.k) + ") does not match the cloud (" +
                       std::to_string(cloud.size()) + " points, needs " + std::to_string(k) + " columns)");
}

}  // namespace

Cleaning removeStatisticalOutliers(const Cloud& cloud, const StatisticalOutlierParams& p, const Progress& progress) {
  checkStatistical(cloud, p);
  return removeStatisticalOutliers(cloud, nearestNeighbours(cloud.points, static_cast<size_t>(p.k_neighbours) + 1, progress),
                                   p, progress);
}

Cleaning removeStatisticalOutliers(const Cloud& cloud, const NeighbourTable& table, const StatisticalOutlierParams& p,
                                   const Progress& progress) {
  checkStatistical(cloud, p);
  const size_t k = static_cast<size_t>(p.k_neighbours) + 1;  // the point itself is row[0]
  checkTable("removeStatisticalOutliers", cloud, table, k);
  std::vector<double> mean_d(cloud.size());
  const long n = static_cast<long>(cloud.size());
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const float* d2 = table.rowDist2(static_cast<size_t>(i));
    double s = 0;
    for (size_t j = 1; j < k; ++j) s += std::sqrt(static_cast<double>(d2[j]));
    mean_d[i] = s / static_cast<double>(k - 1);
  }
  double sum = 0, sum2 = 0;
  for (double d : mean_d) {
    sum += d;
    sum2 += d * d;
  }
  const double mean = sum / static_cast<double>(n);
  const double var = std::max(0.0, sum2 / static_cast<double>(n) - mean * mean);
  Cleaning result;
  result.threshold_m = mean + p.std_ratio * std::sqrt(var);
  for (size_t i = 0; i < cloud.size(); ++i)
    (mean_d[i] <= result.threshold_m ? result.kept : result.removed).push_back(static_cast<uint32_t>(i));
  progress("outliers", 1.0);
  return result;
}

Cleaning removeRadiusOutliers(const Cloud& cloud, const RadiusOutlierParams& p, const Progress& progress) {
  checkRadius(cloud, p);
  const size_t need = static_cast<size_t>(p.min_neighbours) + 1;
  if (cloud.size() < need) return removeRadiusOutliers(cloud, NeighbourTable{}, p, progress);
  // The (min_neighbours + 1)-th nearest point decides: within the radius or not.
  return removeRadiusOutliers(cloud, nearestNeighbours(cloud.points, need, progress), p, progress);
}

Cleaning removeRadiusOutliers(const Cloud& cloud, const NeighbourTable& table, const RadiusOutlierParams& p,
                              const Progress& progress) {
  checkRadius(cloud, p);
  const size_t need = static_cast<size_t>(p.min_neighbours) + 1;
  Cleaning result;
  if (cloud.size() < need) {
    result.removed.resize(cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) result.removed[i] = static_cast<uint32_t>(i);
    result.warnings.push_back("cloud smaller than min_neighbours + 1: every point removed");
    return result;
  }
  checkTable("removeRadiusOutliers", cloud, table, need);
  double radius = p.radius_m;
  if (radius == 0) {
    radius = 4.0 * medianSpacing(table);
  }
  result.threshold_m = radius;
  const float r2 = static_cast<float>(radius * radius);
  for (size_t i = 0; i < cloud.size(); ++i)
    (table.rowDist2(i)[need - 1] <= r2 ? result.kept : result.removed).push_back(static_cast<uint32_t>(i));
  progress("outliers", 1.0);
  return result;
}

Cleaning readmitSurfacePoints(const Cloud& cloud, const std::vector<uint32_t>& kept, const ReadmitParams& p) {
  if (p.k_neighbours < 3)
    throw InvalidInput("[readmitSurfacePoints] k_neighbours must be >= 3 (got " + std::to_string(p.k_neighbours) + ")");
  if (!(p.max_offset_m > 0) || !(p.max_gap_factor > 0))
    throw InvalidInput("[readmitSurfacePoints] max_offset_m and max_gap_factor must be > 0");
  std::vector<char> in(cloud.size(), 0);
  for (uint32_t i : kept) {
    if (i >= cloud.size())
      throw InvalidInput("[readmitSurfacePoints] kept index " + std::to_string(i) + " outside the cloud of " +
                         std::to_string(cloud.size()) + " points");
    in[i] = 1;
  }
  const size_t k = static_cast<size_t>(p.k_neighbours);
  Cleaning result;
  if (kept.size() > k) {
    // One grid over the kept points serves every pass; the points readmitted so far
    // (few) are searched apart and merged in, which gives the k nearest of the
    // whole current membership without rebuilding a tree of it each pass.
    std::vector<Vec3> base;
    base.reserve(kept.size());
    for (uint32_t i : kept) base.push_back(cloud.points[i]);
    const auto grid = gridForNeighbours(base, k);
    const double max_gap = p.max_gap_factor * medianNeighbourDistance(*grid, base, 2);
    std::vector<Vec3> pts = base;  // the current members: base, then the readmitted in order
    std::vector<uint32_t> candidates;
    for (uint32_t i = 0; i < cloud.size(); ++i)
      if (!in[i]) candidates.push_back(i);
    for (int pass = 0; pass < p.passes && !candidates.empty(); ++pass) {
      const std::vector<Vec3> added(pts.begin() + static_cast<long>(base.size()), pts.end());
      const std::unique_ptr<KdTree> added_tree = added.empty() ? nullptr : std::make_unique<KdTree>(added);
      std::vector<char> back(candidates.size(), 0);
      const long nc = static_cast<long>(candidates.size());
      // Removed points within reach of the current members and on their surface;
      // each candidate's answer is written in its own slot (the same every run).
#pragma omp parallel
      {
        std::vector<uint32_t> idx, idx2;
        std::vector<double> d2, d2b;
        std::vector<std::pair<double, uint32_t>> merged;
#pragma omp for schedule(dynamic, 32)
        for (long c = 0; c < nc; ++c) {
          const Vec3& q = cloud.points[candidates[static_cast<size_t>(c)]];
          grid->nearest(q, k, idx, d2);
          if (added_tree) {
            added_tree->nearest(q, k, idx2, d2b);
            merged.clear();
            for (size_t j = 0; j < idx.size(); ++j) merged.emplace_back(d2[j], idx[j]);
            for (size_t j = 0; j < idx2.size(); ++j)
              merged.emplace_back(d2b[j], static_cast<uint32_t>(base.size() + idx2[j]));
            const size_t m = std::min(k, merged.size());
            std::partial_sort(merged.begin(), merged.begin() + static_cast<long>(m), merged.end());
            idx.resize(m);
            d2.resize(m);
            for (size_t j = 0; j < m; ++j) {
              d2[j] = merged[j].first;
              idx[j] = merged[j].second;
            }
          }
          if (idx.size() < 3 || std::sqrt(d2.front()) > max_gap) continue;
          const DetectedPlane plane = fitPlane(pts, idx);
          // Neighbours along a line give no plane to test against.
          if (plane.width_m < 1e-3 * plane.extent_m) continue;
          // Off the plane by no more than the noise allows, or than the neighbours
          // themselves scatter about it where the surface curves within their reach:
          // a gennaker's head curves 2-5 cm away from the plane of the samples 10-25 cm
          // below its last ones, which a noise-only test would leave out, and the head low.
          const double tol = std::max(p.max_offset_m, 3.0 * plane.rms_m);
          if (std::abs(plane.normal.dot(q) - plane.offset_m) <= tol) back[static_cast<size_t>(c)] = 1;
        }
      }
      // Admitted after the pass, so the result does not depend on the visiting order.
      std::vector<uint32_t> rest;
      bool any = false;
      for (size_t c = 0; c < candidates.size(); ++c)
        if (back[c]) {
          any = true;
          in[candidates[c]] = 1;
          pts.push_back(cloud.points[candidates[c]]);
        } else {
          rest.push_back(candidates[c]);
        }
      if (!any) break;
      candidates.swap(rest);
    }
  }
  for (uint32_t i = 0; i < cloud.size(); ++i) (in[i] ? result.kept : result.removed).push_back(i);
  result.threshold_m = p.max_offset_m;
  return result;
}

}  // namespace sailshape
