#include "analysis/smoothing.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "analysis/errors.hpp"
#include "analysis/neighbours.hpp"

namespace sailshape {
namespace {

// A local MLS surface: frame (origin, eu, ev, normal) and the height
// c0 + c1 u + c2 v + c3 u² + c4 uv + c5 v² over (u, v) in units of `scale`.
struct LocalSurface {
  Vec3 origin = Vec3::Zero(), eu = Vec3::UnitX(), ev = Vec3::UnitY(), normal = Vec3::UnitZ();
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  double scale = 1;  // 1 / neighbourhood radius

  Vec3 project(const Vec3& p) const {
    const Vec3 d = p - origin;
    const double u = d.dot(eu), v = d.dot(ev);
    const double us = u * scale, vs = v * scale;
    const double h = c[0] + c[1] * us + c[2] * vs + c[3] * us * us + c[4] * us * vs + c[5] * vs * vs;
    return origin + u * eu + v * ev + h * normal;
  }
};

// Weighted plane, then (order 2) a weighted quadratic height field over it,
// from the neighbours `row` (squared distances d2, the last one the radius²)
// of the point `at`.
LocalSurface fitLocal(const std::vector<Vec3>& pts, const uint32_t* row, const float* d2, size_t k, const Vec3& at,
                      int order, double h2) {
  LocalSurface s;
  h2 = std::max(1e-12, h2);
  thread_local std::vector<double> w;
  w.resize(k);
  double wsum = 0;
  Vec3 mean = Vec3::Zero();
  for (size_t j = 0; j < k; ++j) {
    w[j] = std::exp(-2.0 * static_cast<double>(d2[j]) / h2);  // the radius is 2σ of the weights
    wsum += w[j];
    mean += w[j] * pts[row[j]];
  }
  mean /= wsum;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t j = 0; j < k; ++j) {
    const Vec3 d = pts[row[j]] - mean;
    cov.noalias() += w[j] * d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  s.normal = eig.eigenvectors().col(0);
  s.eu = eig.eigenvectors().col(2);
  s.ev = s.normal.cross(s.eu);
  s.origin = at - s.normal * s.normal.dot(at - mean);
  s.scale = 1.0 / std::sqrt(h2);
  if (order == 2) {
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    for (size_t j = 0; j < k; ++j) {
      const Vec3 d = pts[row[j]] - s.origin;
      const double u = d.dot(s.eu) * s.scale, v = d.dot(s.ev) * s.scale, z = d.dot(s.normal);
      Eigen::Matrix<double, 6, 1> m;
      m << 1, u, v, u * u, u * v, v * v;
      A.noalias() += w[j] * m * m.transpose();
      b.noalias() += w[j] * z * m;
    }
    Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(A);
    const Eigen::Matrix<double, 6, 1> c = ldlt.solve(b);
    if (ldlt.info() == Eigen::Success && c.allFinite()) s.c = c;
  }
  return s;
}

// One anchor per cubic cell of side `cell`: the point nearest the cell's centroid.
std::vector<uint32_t> pickAnchors(const std::vector<Vec3>& pts, double cell) {
  struct Acc {
    Vec3 sum = Vec3::Zero();
    uint32_t count = 0, best = 0;
    double best_d2 = 0;
  };
  auto key = [cell](const Vec3& p) { return voxelKey(p, cell); };
  std::unordered_map<int64_t, Acc> cells;
  cells.reserve(pts.size() / 4 + 1);
  for (const Vec3& p : pts) {
    Acc& a = cells[key(p)];
    a.sum += p;
    ++a.count;
  }
  for (auto& [k, a] : cells) a.best_d2 = std::numeric_limits<double>::infinity();
  for (uint32_t i = 0; i < pts.size(); ++i) {
    Acc& a = cells[key(pts[i])];
    const double d2 = (pts[i] - a.sum / a.count).squaredNorm();
    if (d2 < a.best_d2) {
      a.best_d2 = d2;
      a.best = i;
    }
  }
  std::vector<uint32_t> anchors;
  anchors.reserve(cells.size());
  for (const auto& [k, a] : cells) anchors.push_back(a.best);
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

}  // namespace

Smoothing smoothMls(const Cloud& cloud, const SmoothingParams& p, const Progress& progress) {
  if (p.k_neighbours < 6 || p.k_neighbours > 256)
    throw InvalidInput("[smoothMls] k_neighbours must be in [6, 256] (got " + std::to_string(p.k_neighbours) + ")");
  if (p.polynomial_order != 1 && p.polynomial_order != 2)
    throw InvalidInput("[smoothMls] polynomial_order must be 1 or 2 (got " + std::to_string(p.polynomial_order) + ")");
  if (!(p.good_m > 0) || !(p.fair_m >= p.good_m))
    throw InvalidInput("[smoothMls] need 0 < good_m <= fair_m (got " + std::to_string(p.good_m) + ", " +
                       std::to_string(p.fair_m) + ")");
  if (!(p.anchor_ratio >= 0 && p.anchor_ratio <= 1))
    throw InvalidInput("[smoothMls] anchor_ratio must be in [0, 1] (got " + std::to_string(p.anchor_ratio) + ")");
  const size_t k = static_cast<size_t>(p.k_neighbours);
  if (cloud.size() < k)
    throw InvalidInput("[smoothMls] cloud has " + std::to_string(cloud.size()) + " points, fewer than k_neighbours = " +
                       std::to_string(k));
  const std::vector<Vec3>& pts = cloud.points;
  const long n = static_cast<long>(cloud.size());
  Smoothing result;
  result.cloud = cloud;
  result.displacement_m.resize(cloud.size());

  KdTree tree(pts);
  {
    // The neighbourhood radius, from a sample of points.
    const double radius = medianNeighbourDistance(tree, pts, k, 256);
    std::vector<uint32_t> anchors;
    if (p.anchor_ratio > 0) {
      anchors = pickAnchors(pts, std::max(1e-6, p.anchor_ratio * radius));
    } else {
      anchors.resize(pts.size());
      for (uint32_t i = 0; i < pts.size(); ++i) anchors[i] = i;
    }
    const long na = static_cast<long>(anchors.size());
    std::vector<LocalSurface> surfaces(anchors.size());
    // Neighbourhoods by a uniform grid of cells one radius wide: every point
    // within the radius lies in the 27 cells around the anchor's.
    const double cell = radius;
    std::unordered_map<int64_t, std::vector<uint32_t>> grid;
    grid.reserve(pts.size() / 64 + 1);
    for (uint32_t i = 0; i < pts.size(); ++i) grid[voxelKey(pts[i], cell)].push_back(i);
    const double r2 = radius * radius;
    double radius_sum = 0;
    size_t too_few = 0;
#pragma omp parallel reduction(+ : radius_sum, too_few)
    {
      std::vector<uint32_t> row;
      std::vector<float> rd2;
      std::vector<double> kd2;
#pragma omp for schedule(dynamic, 64)
      for (long a = 0; a < na; ++a) {
        const Vec3& at = pts[anchors[static_cast<size_t>(a)]];
        const Eigen::Vector3i c = voxelOf(at, cell);
        row.clear();
        rd2.clear();
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
              auto it = grid.find(voxelKey(c + Eigen::Vector3i(dx, dy, dz)));
              if (it == grid.end()) continue;
              for (uint32_t j : it->second) {
                const double d2 = (pts[j] - at).squaredNorm();
                if (d2 <= r2) {
                  row.push_back(j);
                  rd2.push_back(static_cast<float>(d2));
                }
              }
            }
        double h2 = r2;
        if (row.size() < k) {  // one-sided (an edge) or sparse: the k nearest instead
          ++too_few;
          tree.nearest(at, k, row, kd2);
          rd2.assign(kd2.begin(), kd2.end());
          h2 = kd2.back();
        }
        surfaces[static_cast<size_t>(a)] = fitLocal(pts, row.data(), rd2.data(), row.size(), at, p.polynomial_order, h2);
        radius_sum += std::sqrt(h2);
      }
    }
    progress("smoothing", 0.6);
    result.mean_radius_m = radius_sum / static_cast<double>(std::max<long>(1, na));
    if (p.anchor_ratio == 0) {
#pragma omp parallel for schedule(static)
      for (long i = 0; i < n; ++i) result.cloud.points[i] = surfaces[static_cast<size_t>(i)].project(pts[i]);
    } else {
      // Each point: a distance-weighted blend of its nearest anchors' projections.
      std::vector<Vec3> anchor_pts(anchors.size());
      for (size_t a = 0; a < anchors.size(); ++a) anchor_pts[a] = pts[anchors[a]];
      KdTree anchor_tree(anchor_pts);
      const size_t blend = std::min<size_t>(4, anchors.size());
#pragma omp parallel
      {
        std::vector<uint32_t> near;
        std::vector<double> nd2;
#pragma omp for schedule(static)
        for (long i = 0; i < n; ++i) {
          anchor_tree.nearest(pts[i], blend, near, nd2);
          const double h2 = std::max(1e-12, nd2.back() * 2.0);
          Vec3 sum = Vec3::Zero();
          double wsum = 0;
          for (size_t j = 0; j < near.size(); ++j) {
            const double w = std::exp(-nd2[j] / h2);
            sum += w * surfaces[near[j]].project(pts[i]);
            wsum += w;
          }
          result.cloud.points[i] = sum / wsum;
        }
      }
    }
  }
  progress("smoothing", 1.0);

  double sum2 = 0;
  for (long i = 0; i < n; ++i) {
    const float d = static_cast<float>((result.cloud.points[i] - pts[i]).norm());
    result.displacement_m[i] = d;
    sum2 += static_cast<double>(d) * d;
    result.max_displacement_m = std::max(result.max_displacement_m, static_cast<double>(d));
    if (d < p.good_m)
      ++result.good;
    else if (d < p.fair_m)
      ++result.fair;
    else
      ++result.bad;
  }
  result.rms_displacement_m = std::sqrt(sum2 / static_cast<double>(n));
  // Pure sensor noise already puts a Gaussian tail beyond fair_m (about 2.4 %
  // for 9 mm at σ = 4 mm); warn only well beyond that.
  const double tail = std::erfc(p.fair_m / (p.good_m * std::sqrt(2.0)));
  const double bad_fraction = static_cast<double>(result.bad) / static_cast<double>(n);
  if (bad_fraction > 2.0 * tail + 0.01)
    result.warnings.push_back(std::to_string(result.bad) + " points (" + std::to_string(100.0 * bad_fraction) +
                              " %) moved more than fair_m = " + std::to_string(p.fair_m) +
                              " m, far more than noise alone explains: the neighbourhood is too large for the "
                              "surface's curvature");
  return result;
}

}  // namespace sailshape
