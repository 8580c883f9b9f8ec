#include "analysis/spatial/normals.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <deque>

#include "analysis/core/errors.hpp"

namespace sailshape {
namespace {

void checkParams(const Cloud& cloud, const NormalParams& p) {
  if (p.k_neighbours < 3)
    throw InvalidInput("[estimateNormals] k_neighbours must be >= 3 (got " + std::to_string(p.k_neighbours) + ")");
  if (p.orientation != "viewpoint" && p.orientation != "propagate" && p.orientation != "none")
    throw InvalidInput("[estimateNormals] orientation must be viewpoint, propagate or none (got '" +
                       p.orientation + "')");
  if (cloud.size() < static_cast<size_t>(p.k_neighbours))
    throw InvalidInput("[estimateNormals] cloud has " + std::to_string(cloud.size()) +
                       " points, fewer than k_neighbours = " + std::to_string(p.k_neighbours));
}

// Flips normals so neighbours agree, breadth first from the flattest point of
// each connected patch of the neighbour graph.
size_t propagateOrientation(const NeighbourTable& table, size_t k, Normals& n) {
  const size_t count = n.normals.size();
  std::vector<char> done(count, 0);
  std::vector<uint32_t> order(count);
  for (size_t i = 0; i < count; ++i) order[i] = static_cast<uint32_t>(i);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return n.curvature[a] < n.curvature[b]; });
  size_t flipped = 0;
  std::deque<uint32_t> queue;
  for (uint32_t seed : order) {
    if (done[seed]) continue;
    done[seed] = 1;
    queue.push_back(seed);
    while (!queue.empty()) {
      const uint32_t cur = queue.front();
      queue.pop_front();
      const uint32_t* row = table.row(cur);
      for (size_t j = 1; j < k; ++j) {
        const uint32_t nb = row[j];
        if (done[nb]) continue;
        done[nb] = 1;
        if (n.normals[nb].dot(n.normals[cur]) < 0) {
          n.normals[nb] = -n.normals[nb];
          ++flipped;
        }
        queue.push_back(nb);
      }
    }
  }
  return flipped;
}

}  // namespace

NormalEstimation estimateNormals(const Cloud& cloud, const NormalParams& params, const Progress& progress) {
  checkParams(cloud, params);
  const NeighbourTable table = nearestNeighbours(cloud.points, static_cast<size_t>(params.k_neighbours), progress);
  return estimateNormals(cloud, table, params, progress);
}

NormalEstimation estimateNormals(const Cloud& cloud, const NeighbourTable& table, const NormalParams& params,
                                 const Progress& progress) {
  checkParams(cloud, params);
  const size_t k = static_cast<size_t>(params.k_neighbours);
  if (table.size() != cloud.size() || table.k < k)
    throw InvalidInput("[estimateNormals] neighbour table (" + std::to_string(table.size()) + " rows, k = " +
                       std::to_string(table.k) + ") does not match the cloud (" + std::to_string(cloud.size()) +
                       " points, k_neighbours = " + std::to_string(k) + ")");
  NormalEstimation result;
  const long n = static_cast<long>(cloud.size());
  result.normals.normals.resize(cloud.size());
  result.normals.curvature.resize(cloud.size());
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    const uint32_t* row = table.row(static_cast<size_t>(i));
    Vec3 mean = Vec3::Zero();
    for (size_t j = 0; j < k; ++j) mean += cloud.points[row[j]];
    mean /= static_cast<double>(k);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t j = 0; j < k; ++j) {
      const Vec3 d = cloud.points[row[j]] - mean;
      cov.noalias() += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    const Vec3 ev = eig.eigenvalues().cwiseMax(0.0);
    const double sum = ev.sum();
    Vec3 normal = eig.eigenvectors().col(0).normalized();
    result.normals.curvature[i] = sum > 0 ? ev[0] / sum : 0.0;
    if (params.robust) {
      // Refit with the neighbours far off the current plane down-weighted
      // (Cauchy weights on 2.5 robust σ), until the normal settles: a sail point
      // beside a mast keeps the sail's normal instead of one tilted towards the mast.
      const size_t kk = std::min<size_t>(k, 512);
      double r[512], sorted[512], w[512];
      Vec3 centre = mean;
      for (int it = 0; it < 4; ++it) {
        for (size_t j = 0; j < kk; ++j) sorted[j] = r[j] = std::abs((cloud.points[row[j]] - centre).dot(normal));
        std::nth_element(sorted, sorted + kk / 2, sorted + kk);
        const double scale = 2.5 * 1.4826 * sorted[kk / 2] + 1e-9;
        double wsum = 0;
        Vec3 wmean = Vec3::Zero();
        for (size_t j = 0; j < kk; ++j) {
          const double t = r[j] / scale;
          w[j] = 1.0 / (1.0 + t * t);
          wsum += w[j];
          wmean += w[j] * cloud.points[row[j]];
        }
        wmean /= wsum;
        Eigen::Matrix3d wcov = Eigen::Matrix3d::Zero();
        for (size_t j = 0; j < kk; ++j) {
          const Vec3 d = cloud.points[row[j]] - wmean;
          wcov.noalias() += w[j] * d * d.transpose();
        }
        eig.computeDirect(wcov);
        const Vec3 next = eig.eigenvectors().col(0).normalized();
        const bool settled = std::abs(next.dot(normal)) > std::cos(0.5 * 3.14159265358979 / 180.0);
        normal = next;
        centre = wmean;
        if (settled) break;
      }
    }
    result.normals.normals[i] = normal;
  }
  progress("normals", 1.0);

  const bool has_viewpoint = cloud.viewpoint.has_value();
  if (params.orientation == "viewpoint" && has_viewpoint) {
    result.orientation = "viewpoint";
    for (size_t i = 0; i < cloud.size(); ++i) {
      if (result.normals.normals[i].dot(*cloud.viewpoint - cloud.points[i]) < 0) {
        result.normals.normals[i] = -result.normals.normals[i];
        ++result.flipped;
      }
    }
  } else if (params.orientation != "none") {
    if (params.orientation == "viewpoint")
      result.warnings.push_back("cloud has no viewpoint; normals oriented by propagation instead");
    result.orientation = "propagate";
    result.flipped = propagateOrientation(table, k, result.normals);
  } else {
    result.orientation = "none";
  }
  return result;
}

}  // namespace sailshape
