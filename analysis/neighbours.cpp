#include "analysis/neighbours.hpp"

#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>
#include <string>

#include "analysis/errors.hpp"

namespace sailshape {
namespace {

struct PointAdaptor {
  const std::vector<Vec3>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointAdaptor>,
                                                 PointAdaptor, 3, uint32_t>;

}  // namespace

struct KdTree::Impl {
  PointAdaptor adaptor;
  Tree tree;
  explicit Impl(const std::vector<Vec3>& points)
      : adaptor{points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree.buildIndex();
  }
};

KdTree::KdTree(const std::vector<Vec3>& points) : impl_(std::make_unique<Impl>(points)) {}
KdTree::~KdTree() = default;

void KdTree::nearest(const Vec3& q, size_t k, std::vector<uint32_t>& indices, std::vector<double>& dist2) const {
  k = std::min(k, impl_->adaptor.pts.size());
  indices.resize(k);
  dist2.resize(k);
  if (k == 0) return;
  const size_t found = impl_->tree.knnSearch(q.data(), k, indices.data(), dist2.data());
  indices.resize(found);
  dist2.resize(found);
}

void KdTree::withinRadius(const Vec3& q, double radius_m, std::vector<uint32_t>& indices,
                          std::vector<double>& dist2) const {
  std::vector<std::pair<uint32_t, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = true;
  impl_->tree.radiusSearch(q.data(), radius_m * radius_m, matches, params);
  indices.resize(matches.size());
  dist2.resize(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    indices[i] = matches[i].first;
    dist2[i] = matches[i].second;
  }
}

NeighbourTable nearestNeighbours(const std::vector<Vec3>& points, size_t k, const Progress& progress) {
  if (k < 1) throw InvalidInput("[nearestNeighbours] k must be >= 1 (got 0)");
  if (points.size() < k)
    throw InvalidInput("[nearestNeighbours] cloud has " + std::to_string(points.size()) +
                       " points, fewer than k = " + std::to_string(k));
  KdTree tree(points);
  NeighbourTable table;
  table.k = k;
  table.index.resize(points.size() * k);
  table.dist2.resize(points.size() * k);
  const long n = static_cast<long>(points.size());
  const long chunk = 8192;
  for (long start = 0; start < n; start += chunk) {
    const long end = std::min(n, start + chunk);
#pragma omp parallel
    {
      std::vector<uint32_t> idx;
      std::vector<double> d2;
#pragma omp for schedule(static)
      for (long i = start; i < end; ++i) {
        tree.nearest(points[i], k, idx, d2);
        // Duplicate points can push the query point itself out of slot 0; put it back.
        auto self = std::find(idx.begin(), idx.end(), static_cast<uint32_t>(i));
        if (self == idx.end()) {
          idx.back() = static_cast<uint32_t>(i);
          d2.back() = 0.0;
          self = idx.end() - 1;
        }
        std::rotate(idx.begin(), self, self + 1);
        std::rotate(d2.begin(), d2.begin() + (self - idx.begin()), d2.begin() + (self - idx.begin()) + 1);
        for (size_t j = 0; j < k; ++j) {
          table.index[i * k + j] = idx[j];
          table.dist2[i * k + j] = static_cast<float>(d2[j]);
        }
      }
    }
    progress("neighbours", static_cast<double>(end) / static_cast<double>(n));
  }
  return table;
}

double medianSpacing(const NeighbourTable& table) {
  if (table.k < 2 || table.size() < 2) return 0.0;
  std::vector<float> d(table.size());
  for (size_t i = 0; i < table.size(); ++i) d[i] = table.rowDist2(i)[1];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return std::sqrt(static_cast<double>(d[d.size() / 2]));
}

double medianNeighbourDistance(const KdTree& tree, const std::vector<Vec3>& points, size_t k, size_t samples) {
  if (points.size() < 2 || k < 2) return 0.0;
  std::vector<double> d;
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  const size_t step = std::max<size_t>(1, points.size() / std::max<size_t>(1, samples));
  for (size_t i = 0; i < points.size(); i += step) {
    tree.nearest(points[i], k, idx, d2);
    d.push_back(std::sqrt(d2.back()));
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

Eigen::Vector3i voxelOf(const Vec3& p, double size) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / size)), static_cast<int>(std::floor(p.y() / size)),
                         static_cast<int>(std::floor(p.z() / size)));
}

int64_t voxelKey(const Eigen::Vector3i& c) {
  return (static_cast<int64_t>(c.x()) * 73856093) ^ (static_cast<int64_t>(c.y()) * 19349663) ^
         (static_cast<int64_t>(c.z()) * 83492791);
}

}  // namespace sailshape
