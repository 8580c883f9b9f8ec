#include "analysis/spatial/direction_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

}  // namespace sailshape
