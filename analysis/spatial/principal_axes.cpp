#include "analysis/spatial/principal_axes.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "analysis/core/fit.hpp"

namespace sailshape {
namespace {

template <typename ForEach>
PrincipalAxes axesOf(size_t n, ForEach&& forEach) {
  PrincipalAxes pa;
  forEach([&](const Vec3& p) { pa.mean += p; });
  pa.mean /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  forEach([&](const Vec3& p) { cov.noalias() += (p - pa.mean) * (p - pa.mean).transpose(); });
  cov /= static_cast<double>(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  pa.axes = eig.eigenvectors();
  pa.variance = eig.eigenvalues().cwiseMax(0.0);
  return pa;
}

}  // namespace

PrincipalAxes principalAxes(const std::vector<Vec3>& points) {
  return axesOf(points.size(), [&](auto&& f) {
    for (const Vec3& p : points) f(p);
  });
}

PrincipalAxes principalAxes(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices) {
  return axesOf(indices.size(), [&](auto&& f) {
    for (uint32_t i : indices) f(points[i]);
  });
}

HeightFieldSpread quadraticHeightFieldSpread(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices,
                                             const PrincipalAxes& pa) {
  // Plane coordinates in units of the longest spread keep the normal equations well
  // conditioned; the residual does not depend on that scale.
  const double s = 1.0 / std::max(1e-12, std::sqrt(pa.variance[2]));
  const Vec3 eu = s * pa.axes.col(2), ev = s * pa.axes.col(1), n = pa.axes.col(0);
  QuadraticHeightField field;
  for (uint32_t i : indices) {
    const Vec3 d = points[i] - pa.mean;
    field.add(d.dot(eu), d.dot(ev), d.dot(n));
  }
  // Fewer than 6 points in general position leave the fit singular; its residual
  // is still held within the plane's.
  field.solve();
  HeightFieldSpread out;
  out.plane_ss_m2 = field.height_ss;
  out.points = indices.size();
  out.residual_ss_m2 = field.residualSumOfSquares();
  return out;
}

}  // namespace sailshape
