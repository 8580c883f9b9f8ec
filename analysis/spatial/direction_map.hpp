#pragma once
// The scene as a scanner saw it: each point's direction from the scanner on a grid
// of unit vectors `cell` radians wide, and the nearest range in each cell. A beam
// towards direction u met nothing nearer than nearest(u) (within a cell each way).
// What tells a shadow on a sail (analysis/outline/coverage.cpp) and a scanner's
// mirror image (viewpoint_estimate.cpp).
#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

class DirectionMap {
 public:
  DirectionMap(const std::vector<Vec3>& points, const Vec3& scanner, double cell);
  // The nearest range among the cells around direction u (unit), or +∞.
  double nearest(const Vec3& u) const;

 private:
  Eigen::Vector3i index(const Vec3& u) const;
  static uint64_t pack(const Eigen::Vector3i& i);

  double cell_;
  std::unordered_map<uint64_t, double> nearest_;
};

// The coarser step of the angular grid the points were sampled on from `scanner`,
// radians. A unit on a turntable samples on a grid of two steps: along its scan
// lines (0.1667-1°, SPEC §3) and between them (the turntable's). A point's nearest
// direction is its neighbour at the finer step; its nearest neighbour at more than
// 60° from that line is across it, at the coarser step. The median of that angle
// over up to 2,000 points spread through the cloud; a DirectionMap at least this
// wide holds a sample of every surface in the cells around any direction the
// scanner looked. 0 when no point has a neighbour across its line.
double angularGridStep(const std::vector<Vec3>& points, const Vec3& scanner);

}  // namespace sailshape
