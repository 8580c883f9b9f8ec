#include "analysis/spatial/direction_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/spatial/neighbours.hpp"

namespace sailshape {

DirectionMap::DirectionMap(const std::vector<Vec3>& points, const Vec3& scanner, double cell) : cell_(cell) {
  for (const Vec3& p : points) {
    const Vec3 d = p - scanner;
    const double r = d.norm();
    if (r <= 0) continue;
    auto [it, fresh] = nearest_.try_emplace(pack(index(d / r)), r);
    if (!fresh) it->second = std::min(it->second, r);
  }
}

double DirectionMap::nearest(const Vec3& u) const {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3i c = index(u);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        auto it = nearest_.find(pack(c + Eigen::Vector3i(dx, dy, dz)));
        if (it != nearest_.end()) best = std::min(best, it->second);
      }
  return best;
}

Eigen::Vector3i DirectionMap::index(const Vec3& u) const {
  return Eigen::Vector3i(static_cast<int>(std::floor(u.x() / cell_)), static_cast<int>(std::floor(u.y() / cell_)),
                         static_cast<int>(std::floor(u.z() / cell_)));
}

uint64_t DirectionMap::pack(const Eigen::Vector3i& i) {
  auto part = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v + (1 << 20)) & 0x1fffff); };
  return part(i.x()) | part(i.y()) << 21 | part(i.z()) << 42;
}

double angularGridStep(const std::vector<Vec3>& points, const Vec3& scanner) {
  std::vector<Vec3> directions;
  directions.reserve(points.size());
  for (const Vec3& p : points) {
    const Vec3 d = p - scanner;
    if (d.norm() > 0) directions.push_back(d.normalized());
  }
  if (directions.size() < 5) return 0;
  const KdTree tree(directions);
  const size_t stride = std::max<size_t>(1, directions.size() / 2000);
  std::vector<double> across;
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  // 16 neighbours reach across a line on grids whose steps differ up to sevenfold.
  for (size_t i = 0; i < directions.size(); i += stride) {
    tree.nearest(directions[i], 16, idx, d2);  // the point itself first
    if (idx.size() < 3) continue;
    const Vec3 along = (directions[idx[1]] - directions[i]).normalized();
    for (size_t j = 2; j < idx.size(); ++j) {
      const Vec3 step = directions[idx[j]] - directions[i];
      if (std::abs(step.normalized().dot(along)) < 0.5) {
        across.push_back(2.0 * std::asin(std::min(1.0, 0.5 * step.norm())));
        break;
      }
    }
  }
  if (across.empty()) return 0;
  std::nth_element(across.begin(), across.begin() + static_cast<long>(across.size() / 2), across.end());
  return across[across.size() / 2];
}

}  // namespace sailshape
