#include "analysis/spars.hpp"

#include <algorithm>
#include <cmath>

#include "analysis/errors.hpp"

namespace sailshape {

double distanceToSpar(const Vec3& p, const Spar& s) {
  const double along = (p - s.base).dot(s.axis);
  const double radial = (p - s.base - along * s.axis).norm() - s.radius_m;
  return std::max({radial, along - s.length_m, -along});
}

SparFit fitSpar(const Cloud& cloud, const Spar& nominal, const SparFitParams& p) {
  if (!(nominal.axis.norm() > 0) || !(nominal.length_m > 0) || !(nominal.radius_m > 0))
    throw InvalidInput("[fitSpar] spar '" + nominal.name + "' needs an axis, a length and a radius");
  if (!(p.search_m > 0) || !(p.sensor_sigma_m > 0))
    throw InvalidInput("[fitSpar] search_m and sensor_sigma_m must be > 0");
  Spar s = nominal;
  s.axis.normalize();
  const Vec3 u = s.axis.unitOrthogonal(), v = s.axis.cross(u);
  // Sideways coordinates (relative to the nominal axis) of the points near it.
  const double reach = s.radius_m + p.search_m + 3 * p.sensor_sigma_m;
  std::vector<Eigen::Vector2d> q;
  for (const Vec3& x : cloud.points) {
    const Vec3 d = x - s.base;
    const double along = d.dot(s.axis);
    if (along < 0 || along > s.length_m) continue;
    const Eigen::Vector2d w(d.dot(u), d.dot(v));
    if (w.norm() <= reach) q.push_back(w);
  }
  SparFit fit;
  fit.spar = s;
  const double band = 2 * p.sensor_sigma_m;
  auto support = [&](const Eigen::Vector2d& c) {
    size_t n = 0;
    for (const auto& w : q) n += std::abs((w - c).norm() - s.radius_m) <= band;
    return n;
  };
  // Vote: every 2 mm offset within the search disc; the one most points fit wins.
  const double step = 0.002;
  const int steps = static_cast<int>(std::ceil(p.search_m / step));
  Eigen::Vector2d best = Eigen::Vector2d::Zero();
  size_t best_n = 0;
  for (int i = -steps; i <= steps; ++i)
    for (int j = -steps; j <= steps; ++j) {
      const Eigen::Vector2d c(i * step, j * step);
      if (c.norm() > p.search_m) continue;
      const size_t n = support(c);
      // Ties go to the offset nearest the nominal place.
      if (n > best_n || (n == best_n && c.norm() < best.norm())) {
        best_n = n;
        best = c;
      }
    }
  if (best_n < p.min_support) {
    fit.message = "spar '" + s.name + "': " + std::to_string(best_n) + " points on its surface within " +
                  std::to_string(p.search_m) + " m of its nominal place (needs " + std::to_string(p.min_support) + ")";
    return fit;
  }
  // Gauss–Newton on the centre with the radius held, over the points in the band.
  Eigen::Vector2d c = best;
  for (int it = 0; it < 10; ++it) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d b = Eigen::Vector2d::Zero();
    for (const auto& w : q) {
      const Eigen::Vector2d d = w - c;
      const double r = d.norm();
      if (r <= 0 || std::abs(r - s.radius_m) > band) continue;
      const Eigen::Vector2d g = -d / r;  // d(residual)/d(centre)
      A += g * g.transpose();
      b -= g * (r - s.radius_m);
    }
    if (std::abs(A.determinant()) < 1e-18) break;  // the points do not pin the centre down
    const Eigen::Vector2d delta = A.ldlt().solve(b);
    c += delta;
    if (delta.norm() < 1e-6) break;
  }
  double sum2 = 0;
  size_t n = 0;
  for (const auto& w : q) {
    const double r = (w - c).norm() - s.radius_m;
    if (std::abs(r) <= band) {
      sum2 += r * r;
      ++n;
    }
  }
  fit.found = n >= p.min_support;
  fit.support = n;
  fit.rms_m = n ? std::sqrt(sum2 / static_cast<double>(n)) : 0;
  fit.offset = c.x() * u + c.y() * v;
  fit.spar.base = s.base + fit.offset;
  if (!fit.found) {
    fit.spar = s;
    fit.offset = Vec3::Zero();
    fit.message = "spar '" + s.name + "': the refined fit keeps only " + std::to_string(n) + " supporting points";
  }
  return fit;
}

}  // namespace sailshape
