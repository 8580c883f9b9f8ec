#include "analysis/cleaning.hpp"

#include <cmath>

#include "analysis/errors.hpp"
#include "analysis/neighbours.hpp"

namespace sailshape {

Cleaning removeStatisticalOutliers(const Cloud& cloud, const StatisticalOutlierParams& p, const Progress& progress) {
  if (p.k_neighbours < 1)
    throw InvalidInput("[removeStatisticalOutliers] k_neighbours must be >= 1 (got " +
                       std::to_string(p.k_neighbours) + ")");
  if (!(p.std_ratio > 0))
    throw InvalidInput("[removeStatisticalOutliers] std_ratio must be > 0 (got " + std::to_string(p.std_ratio) + ")");
  const size_t k = static_cast<size_t>(p.k_neighbours) + 1;  // the point itself is row[0]
  if (cloud.size() < k)
    throw InvalidInput("[removeStatisticalOutliers] cloud has " + std::to_string(cloud.size()) +
                       " points, needs more than k_neighbours = " + std::to_string(p.k_neighbours));
  const NeighbourTable table = nearestNeighbours(cloud.points, k, progress);
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
  if (p.radius_m < 0 || !std::isfinite(p.radius_m))
    throw InvalidInput("[removeRadiusOutliers] radius_m must be >= 0 (got " + std::to_string(p.radius_m) + ")");
  if (p.min_neighbours < 1)
    throw InvalidInput("[removeRadiusOutliers] min_neighbours must be >= 1 (got " +
                       std::to_string(p.min_neighbours) + ")");
  if (cloud.size() < 2) throw InvalidInput("[removeRadiusOutliers] cloud has fewer than 2 points");
  const size_t need = static_cast<size_t>(p.min_neighbours) + 1;
  Cleaning result;
  if (cloud.size() < need) {
    result.removed.resize(cloud.size());
    for (size_t i = 0; i < cloud.size(); ++i) result.removed[i] = static_cast<uint32_t>(i);
    result.warnings.push_back("cloud smaller than min_neighbours + 1: every point removed");
    return result;
  }
  // The (min_neighbours + 1)-th nearest point decides: within the radius or not.
  const NeighbourTable table = nearestNeighbours(cloud.points, need, progress);
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

}  // namespace sailshape
