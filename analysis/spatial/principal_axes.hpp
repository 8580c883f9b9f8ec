#pragma once
// The best-fit plane of a set of points (their mean and the principal axes of their
// scatter), and how far the points leave it: one implementation for every stage that
// asks.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

struct PrincipalAxes {
  Vec3 mean = Vec3::Zero();
  // Unit axes as columns, by rising variance: col(0) is the best-fit plane's normal,
  // col(2) the direction the points spread along most.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Vec3 variance = Vec3::Zero();  // per point along each axis, m² (never negative)
};

// Of all `points`, or of those at `indices`; needs at least one point.
PrincipalAxes principalAxes(const std::vector<Vec3>& points);
PrincipalAxes principalAxes(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices);

// The points at `indices` measured off the plane of `axes`: the least-squares quadratic
// height field h(u, v) over it (u along col(2), v along col(1)) takes up the bend, the
// residual is what no smooth surface explains. Needs at least 6 points for a residual
// with degrees of freedom left.
struct HeightFieldSpread {
  double plane_ss_m2 = 0;     // sum of squared heights off the plane
  double residual_ss_m2 = 0;  // sum of squared residuals off the quadratic
  size_t points = 0;
};
HeightFieldSpread quadraticHeightFieldSpread(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices,
                                             const PrincipalAxes& axes);

}  // namespace sailshape
