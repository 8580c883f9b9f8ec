#include "analysis/segmentation/spars.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <tuple>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {

Vec3 acrossAxis(const Vec3& d, const Vec3& axis) { return d - d.dot(axis) * axis; }

double sparRunGapM(double radius_m, double sensor_sigma_m) { return 4 * radius_m + 4 * sensor_sigma_m; }

double distanceToSpar(const Vec3& p, const Spar& s) {
  const double along = (p - s.base).dot(s.axis);
  const double radial = acrossAxis(p - s.base, s.axis).norm() - s.radius_m;
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
  std::vector<int> part;  // which tenth of the spar's length each lies along
  for (const Vec3& x : cloud.points) {
    const Vec3 d = x - s.base;
    const double along = d.dot(s.axis);
    if (along < 0 || along > s.length_m) continue;
    const Eigen::Vector2d w(d.dot(u), d.dot(v));
    if (w.norm() > reach) continue;
    q.push_back(w);
    part.push_back(std::min(9, static_cast<int>(10.0 * along / s.length_m)));
  }
  SparFit fit;
  fit.spar = s;
  const double band = 2 * p.sensor_sigma_m;
  // Points on the round surface for it; points inside it against it, as a solid spar
  // returns nothing from within: a cylinder straddling a sail, which crosses its
  // surface twice, has the sail's strip between the crossings inside. (A 25 mm mast
  // 3 m off shows on two or three scan lines, a sail crossing it on two: with a line
  // lost, the straddling place won and the mast was put on the luff, 6 cm aft.)
  // And a spar runs its whole length: a place whose surface points stand on less than
  // half of it is something else's (a sail's luff strip, the mast's foot and head when
  // the scan lost the lines on its body), and the spar is not found there.
  constexpr long kShort = std::numeric_limits<long>::min() + 1;  // surface points on less than half the length
  auto support = [&](const Eigen::Vector2d& c, size_t* on = nullptr) {
    long n = 0;
    size_t surface = 0;
    std::array<bool, 10> seen{};
    for (size_t k = 0; k < q.size(); ++k) {
      const double r = (q[k] - c).norm() - s.radius_m;
      if (std::abs(r) <= band) {
        ++surface;
        seen[static_cast<size_t>(part[k])] = true;
      } else if (r < -band) {
        --n;
      }
    }
    if (on) *on = surface;
    if (std::count(seen.begin(), seen.end(), true) < 5) return kShort;
    return n + static_cast<long>(surface);
  };
  // Vote: every 2 mm offset within the search disc; the best score wins.
  const double step = 0.002;
  const int steps = static_cast<int>(std::ceil(p.search_m / step));
  Eigen::Vector2d best = Eigen::Vector2d::Zero();
  long best_score = std::numeric_limits<long>::min();
  size_t best_n = 0;
  for (int i = -steps; i <= steps; ++i)
    for (int j = -steps; j <= steps; ++j) {
      const Eigen::Vector2d c(i * step, j * step);
      if (c.norm() > p.search_m) continue;
      size_t n = 0;
      const long score = support(c, &n);
      // Ties go to the offset nearest the nominal place.
      if (score > best_score || (score == best_score && c.norm() < best.norm())) {
        best_score = score;
        best_n = n;
        best = c;
      }
    }
  if (best_score == kShort) {
    fit.message = "spar '" + s.name + "': no place within " + formatFixed(p.search_m) +
                  " m of its nominal place has points on its surface along half its length";
    return fit;
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

namespace {

// An infinite round cylinder: a point on its axis, the unit axis and the radius.
struct Cylinder {
  Vec3 point = Vec3::Zero(), axis = Vec3::UnitZ();
  double radius = 0;
};

double radialResidual(const Vec3& p, const Cylinder& c) {
  const Vec3 d = p - c.point;
  return acrossAxis(d, c.axis).norm() - c.radius;
}

// The cylinder through two surface points with their normals: the axis is
// across both normals, and in the plane across the axis both normal lines pass
// through the centre. Nothing when the normals are too near parallel to give an
// axis or the two radii disagree.
std::optional<Cylinder> cylinderThrough(const Vec3& p1, const Vec3& n1, const Vec3& p2, const Vec3& n2,
                                        double tolerance_m) {
  Vec3 axis = n1.cross(n2);
  const double s = axis.norm();
  if (s < 0.25) return std::nullopt;  // normals within ~15° of each other
  axis /= s;
  const Vec3 m1 = (n1 - n1.dot(axis) * axis).normalized(), m2 = (n2 - n2.dot(axis) * axis).normalized();
  const Vec3 q1 = p1 - p1.dot(axis) * axis, q2 = p2 - p2.dot(axis) * axis;
  Eigen::Matrix<double, 3, 2> M;
  M.col(0) = m1;
  M.col(1) = -m2;
  const Eigen::Vector2d tu = M.colPivHouseholderQr().solve(q2 - q1);
  const double r1 = std::abs(tu(0)), r2 = std::abs(tu(1));
  if (std::abs(r1 - r2) > tolerance_m + 0.25 * std::max(r1, r2)) return std::nullopt;
  Cylinder c;
  c.axis = axis;
  c.point = q1 + tu(0) * m1;
  c.radius = 0.5 * (r1 + r2);
  return c;
}

// Whether two round surfaces could be one: axes within 5° and radii within a quarter.
bool parallelAndAsThick(const Vec3& axis_a, double radius_a, const Vec3& axis_b, double radius_b) {
  return std::abs(axis_a.dot(axis_b)) >= std::cos(5.0 * kRadPerDeg) &&
         std::abs(radius_a - radius_b) <= 0.25 * std::max(radius_a, radius_b);
}

// Whether two cylinders are near-copies: parallel and as thick, and each axis within
// half the radius of the other's.
bool alike(const Cylinder& a, const Cylinder& b) {
  return parallelAndAsThick(a.axis, a.radius, b.axis, b.radius) &&
         acrossAxis(b.point - a.point, a.axis).norm() <= 0.5 * std::max(a.radius, b.radius);
}

// Along-axis position and angle around the axis of p.
struct AxialPosition {
  double along, angle;
};
AxialPosition axialPosition(const Vec3& p, const Cylinder& c) {
  const Vec3 u = c.axis.unitOrthogonal(), v = c.axis.cross(u);
  const Vec3 d = p - c.point;
  return {d.dot(c.axis), std::atan2(d.dot(v), d.dot(u))};
}

// The arc the angles (radians) span around the axis, in degrees: 360° less the widest
// gap between them, leaving out angles with fewer than `min_count` (and a tenth of an
// even share per 10°) within 5° either side. A turntable scanner's vertical fans cross
// an upright mast in a few lines, each at about one angle: what matters is how far round
// they reach, not how much of the arc between them is filled.
double spannedArcDeg(const std::vector<double>& angles, double min_count = 3) {
  const size_t n = angles.size();
  std::vector<double> deg(3 * n);
  for (size_t i = 0; i < n; ++i) deg[i] = angles[i] * kDegPerRad;
  std::sort(deg.begin(), deg.begin() + static_cast<long>(n));
  for (size_t i = 0; i < n; ++i) {
    deg[n + i] = deg[i] + 360.0;
    deg[2 * n + i] = deg[i] + 720.0;
  }
  const double need = std::max(min_count, 0.1 * static_cast<double>(n) / 36.0);
  std::vector<double> held;
  for (size_t i = n; i < 2 * n; ++i) {
    const auto lo = std::lower_bound(deg.begin(), deg.end(), deg[i] - 5.0);
    const auto hi = std::upper_bound(deg.begin(), deg.end(), deg[i] + 5.0);
    if (static_cast<double>(hi - lo) >= need) held.push_back(deg[i]);
  }
  if (held.empty()) return 0.0;
  double widest = 360.0 - (held.back() - held.front());  // the gap across 360°
  for (size_t i = 1; i < held.size(); ++i) widest = std::max(widest, held[i] - held[i - 1]);
  return 360.0 - widest;
}

// Whether the angles (radians) of a stretch of points on a spar's surface go round it
// by need_deg: as scan lines do, each a few points at about one angle (spannedArcDeg
// with two within 5°), or as sparse samples do, six or more no 20° of which holds half.
// A line along one side with a stray point or two does neither.
bool goesRound(const std::vector<double>& angles, double need_deg) {
  if (spannedArcDeg(angles, 2) >= need_deg) return true;
  const size_t n = angles.size();
  if (n < 6 || spannedArcDeg(angles, 1) < need_deg) return false;
  std::vector<double> deg(2 * n);
  for (size_t i = 0; i < n; ++i) deg[i] = angles[i] * kDegPerRad;
  std::sort(deg.begin(), deg.begin() + static_cast<long>(n));
  for (size_t i = 0; i < n; ++i) deg[n + i] = deg[i] + 360.0;
  size_t densest = 0;
  for (size_t i = 0, j = 0; i < n; ++i) {
    j = std::max(j, i);
    while (j < 2 * n && deg[j] < deg[i] + 20.0) ++j;
    densest = std::max(densest, j - i);
  }
  return 2 * densest <= n;
}

// The widest arc of a cylinder of `radius` that a flat strip can lie within `band` of:
// a plane radius - band from the axis stays within the band out to 2√(radius·band)
// either side.
double flatStripArcDeg(double radius, double band) {
  if (radius <= band) return 360.0;
  return 2.0 * std::atan(2.0 * std::sqrt(radius * band) / (radius - band)) * kDegPerRad;
}

// Gauss–Newton on the axis position (2), direction (2) and radius (1) over the points
// within `band` of the current surface, re-selecting them each round. On a sparse mast a
// rough hypothesis holds a metre or so of it; each round takes in a little more, so a
// dozen rounds can leave it holding a fraction of the mast (40 take all, and stop early
// when converged).
Cylinder refineCylinder(const std::vector<Vec3>& pts, Cylinder c, double band) {
  for (int it = 0; it < 40; ++it) {
    std::vector<const Vec3*> in;
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& p : pts)
      if (std::abs(radialResidual(p, c)) <= band) {
        in.push_back(&p);
        centroid += p;
      }
    if (in.size() < 6) break;
    centroid /= static_cast<double>(in.size());
    c.point += (centroid - c.point).dot(c.axis) * c.axis;  // keep the axis point among the points
    const Vec3 u = c.axis.unitOrthogonal(), v = c.axis.cross(u);
    auto moved = [&](const Eigen::Matrix<double, 5, 1>& x) {
      Cylinder m;
      m.point = c.point + x(0) * u + x(1) * v;
      m.axis = (c.axis + x(2) * u + x(3) * v).normalized();
      m.radius = c.radius + x(4);
      return m;
    };
    Eigen::Matrix<double, 5, 5> A = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> b = Eigen::Matrix<double, 5, 1>::Zero();
    const double h = 1e-6;
    std::array<Cylinder, 5> stepped;
    for (int k = 0; k < 5; ++k) {
      Eigen::Matrix<double, 5, 1> x = Eigen::Matrix<double, 5, 1>::Zero();
      x(k) = h;
      stepped[static_cast<size_t>(k)] = moved(x);
    }
    for (const Vec3* p : in) {
      const double r0 = radialResidual(*p, c);
      Eigen::Matrix<double, 5, 1> g;
      for (int k = 0; k < 5; ++k) g(k) = (radialResidual(*p, stepped[static_cast<size_t>(k)]) - r0) / h;
      A += g * g.transpose();
      b -= g * r0;
    }
    const Eigen::Matrix<double, 5, 1> dx = A.ldlt().solve(b);
    if (!dx.allFinite()) break;
    c = moved(dx);
    if (dx.head<2>().norm() < 1e-6 && dx.segment<2>(2).norm() < 1e-7 && std::abs(dx(4)) < 1e-6) break;
  }
  return c;
}

// The arc round a spar of `radius` its points must span: min_arc_deg, and a quarter more
// than a flat strip could lie within the band at that radius.
double minArcDeg(double radius, const SparSearchParams& p) {
  return std::max(p.min_arc_deg, 1.25 * flatStripArcDeg(radius, 2 * p.sensor_sigma_m));
}

// A refined cylinder that passed as a spar: its points on the surface as (along, angle)
// sorted along, with their indices into the searched points, and the run [first, last]
// of them without a gap.
struct Candidate {
  Cylinder cylinder;
  std::vector<std::pair<double, double>> on;
  std::vector<uint32_t> index;
  size_t first = 0, last = 0;
  double rms_m = 0;
};

// The fraction of points[indices] within `band` of their least-squares plane.
double fractionOnPlane(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices, double band) {
  if (indices.size() < 3) return 1.0;
  const PrincipalAxes pa = principalAxes(points, indices);
  const Vec3 normal = pa.axes.col(0);
  size_t in = 0;
  for (uint32_t i : indices) in += std::abs((points[i] - pa.mean).dot(normal)) <= band;
  return static_cast<double>(in) / static_cast<double>(indices.size());
}

// Whether the cylinder is a spar among `pts`: within the radius limits, with at least
// min_support points on its surface in one run along it without a gap of two diameters,
// that run min_length_radii long, spanning round the axis at least min_arc_deg and a
// quarter more than a flat strip could lie within the band at its radius, and not lying
// (nine in ten of them) within the band of one plane: two scan lines crossing a mast fit
// any cylinder through both, at a radius that makes them span a wide arc.
std::optional<Candidate> asSpar(const std::vector<Vec3>& pts, const Cylinder& c, const SparSearchParams& p) {
  const double band = 2 * p.sensor_sigma_m;
  if (!(c.radius >= p.min_radius_m && c.radius <= p.max_radius_m)) return std::nullopt;
  Candidate k;
  k.cylinder = c;
  struct OnSurface {
    double along, angle;
    uint32_t index;
    bool operator<(const OnSurface& o) const { return std::tie(along, index) < std::tie(o.along, o.index); }
  };
  std::vector<OnSurface> on;
  double sum2 = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const double r = radialResidual(pts[i], c);
    if (std::abs(r) > band) continue;
    const AxialPosition a = axialPosition(pts[i], c);
    on.push_back({a.along, a.angle, static_cast<uint32_t>(i)});
    sum2 += r * r;
  }
  if (on.size() < p.min_support) return std::nullopt;
  std::sort(on.begin(), on.end());
  for (const OnSurface& o : on) {
    k.on.emplace_back(o.along, o.angle);
    k.index.push_back(o.index);
  }
  k.rms_m = std::sqrt(sum2 / static_cast<double>(k.on.size()));
  // The spar runs as far as its points do without a gap: out from the median, up to the
  // last point before a gap of more than two diameters (an infinite cylinder also grazes
  // whatever lies further along its line).
  const double max_gap = sparRunGapM(c.radius, p.sensor_sigma_m);
  k.first = k.last = k.on.size() / 2;
  while (k.first > 0 && k.on[k.first].first - k.on[k.first - 1].first <= max_gap) --k.first;
  while (k.last + 1 < k.on.size() && k.on[k.last + 1].first - k.on[k.last].first <= max_gap) ++k.last;
  if (k.on[k.last].first - k.on[k.first].first < p.min_length_radii * c.radius) return std::nullopt;
  // A spar is round: its points span more of its girth than any flat strip could.
  std::vector<double> angle;
  for (size_t i = k.first; i <= k.last; ++i) angle.push_back(k.on[i].second);
  if (spannedArcDeg(angle) < minArcDeg(c.radius, p)) return std::nullopt;
  const std::vector<uint32_t> run(k.index.begin() + static_cast<long>(k.first),
                                  k.index.begin() + static_cast<long>(k.last) + 1);
  if (fractionOnPlane(pts, run, band) >= 0.9) return std::nullopt;
  return k;
}

// Whether spar b lies on a's line: axes within 5°, radii within a quarter, and b's axis
// within a radius of a's where the two are nearest (over their overlap along a's axis,
// or at b's end facing a across a gap). A sparse stretch's axis can lean a degree off.
bool onTheLineOf(const Spar& a, const Spar& b) {
  if (!parallelAndAsThick(a.axis, a.radius_m, b.axis, b.radius_m)) return false;
  const double cos_ab = a.axis.dot(b.axis);
  const double b0 = (b.base - a.base).dot(a.axis), b1 = b0 + b.length_m * cos_ab;
  const double lo = std::max(0.0, std::min(b0, b1)), hi = std::min(a.length_m, std::max(b0, b1));
  // Where along a to compare: the overlap's middle, or the end of b facing a.
  const double t = lo <= hi ? 0.5 * (lo + hi) : (std::max(b0, b1) < 0 ? std::max(b0, b1) : std::min(b0, b1));
  const Vec3 on_b = b.base + ((t - b0) / cos_ab) * b.axis;
  return acrossAxis(on_b - a.base, a.axis).norm() <= a.radius_m;
}

// One spar of a and b (b on a's line), each with the points on its surface: the
// cylinder refitted on both sets of points from the better supported one's, running
// over both and over the gap between.
SparFit mergeSpars(const SparFit& a, const std::vector<Vec3>& a_points, const SparFit& b,
                   const std::vector<Vec3>& b_points, double band) {
  const SparFit& lead = a.support >= b.support ? a : b;
  Cylinder c;
  c.point = lead.spar.base;
  c.axis = lead.spar.axis;
  c.radius = lead.spar.radius_m;
  std::vector<Vec3> both = a_points;
  both.insert(both.end(), b_points.begin(), b_points.end());
  c = refineCylinder(both, c, band);
  SparFit m = a;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum2 = 0;
  size_t n = 0;
  for (const Spar* s : {&a.spar, &b.spar})
    for (const Vec3& end : {s->base, Vec3(s->base + s->length_m * s->axis)}) {
      const double along = (end - c.point).dot(c.axis);
      lo = std::min(lo, along);
      hi = std::max(hi, along);
    }
  for (const Vec3& x : both) {
    const double r = radialResidual(x, c);
    if (std::abs(r) > band) continue;
    sum2 += r * r;
    ++n;
  }
  m.spar.axis = c.axis;
  m.spar.base = c.point + lo * c.axis;
  m.spar.length_m = hi - lo;
  m.spar.radius_m = c.radius;
  m.support = n;
  m.rms_m = n ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
  return m;
}

}  // namespace

SparSearch findSpars(const Cloud& cloud, const std::vector<Vec3>& normals, const std::vector<uint32_t>& candidates,
                     const SparSearchParams& p, const std::vector<uint32_t>& length_from) {
  if (normals.size() != cloud.size())
    throw InvalidInput("[findSpars] " + std::to_string(normals.size()) + " normals for " +
                       std::to_string(cloud.size()) + " points");
  if (!(p.sensor_sigma_m > 0) || !(p.min_radius_m > 0) || !(p.max_radius_m > p.min_radius_m) ||
      p.hypotheses < 1 || p.max_spars < 0)
    throw InvalidInput("[findSpars] needs sensor_sigma_m > 0, 0 < min_radius_m < max_radius_m, hypotheses >= 1");
  for (const auto* list : {&candidates, &length_from})
    for (uint32_t i : *list)
      if (i >= cloud.size())
        throw InvalidInput("[findSpars] " + std::string(list == &candidates ? "candidate" : "length_from") +
                           " index " + std::to_string(i) + " beyond the cloud's " + std::to_string(cloud.size()) +
                           " points");
  SparSearch out;
  const double band = 2 * p.sensor_sigma_m;
  std::vector<uint32_t> pool = candidates;
  std::vector<std::vector<Vec3>> held;  // the points on each found spar's surface
  std::mt19937 rng(p.seed);
  for (int s = 0; s < p.max_spars && pool.size() >= std::max<size_t>(p.min_support, 2); ++s) {
    std::vector<Vec3> pts;
    pts.reserve(pool.size());
    for (uint32_t i : pool) pts.push_back(cloud.points[i]);
    // Score hypotheses on at most 20,000 of the points (every n-th); refine on all.
    const size_t stride = std::max<size_t>(1, pts.size() / 20000);
    std::uniform_int_distribution<size_t> pick(0, pool.size() - 1);
    // The second point of a pair comes from within a spar's diameter of the first
    // (as NAPSAC samples): a boom's few hundred points beside a deck's tens of
    // thousands still pair up on most draws that start on the boom.
    const double reach = 2 * p.max_radius_m;
    const PointGrid grid(pts, reach);
    std::vector<uint32_t> around;
    std::vector<double> around_d2;
    auto scoreOf = [&](const Cylinder& c, double within) {
      size_t score = 0;
      for (size_t k = 0; k < pts.size(); k += stride) score += std::abs(radialResidual(pts[k], c)) <= within;
      return score;
    };
    // Two points' normals give a rough cylinder (a few mm of noise in a normal
    // moves a thin spar's axis by centimetres): the best few hypotheses are each
    // refined on their points, and the one the most points then fit wins.
    // Twelve: in a sparse scene the mast's rough hypotheses can rank below fat cylinders
    // through its flank and the luff beside it, so the best few alone may leave it out.
    constexpr size_t kRefined = 12;
    std::vector<std::pair<size_t, Cylinder>> top;  // (score, hypothesis), best first
    for (int h = 0; h < p.hypotheses; ++h) {
      const size_t i = pick(rng);
      grid.withinRadius(pts[i], reach, around, around_d2);
      if (around.size() < 2) continue;
      const size_t j = around[std::uniform_int_distribution<size_t>(0, around.size() - 1)(rng)];
      if (i == j) continue;
      const auto c = cylinderThrough(pts[i], normals[pool[i]], pts[j], normals[pool[j]], 4 * p.sensor_sigma_m);
      if (!c || c->radius < p.min_radius_m || c->radius > p.max_radius_m) continue;
      const size_t score = scoreOf(*c, band);
      if (top.size() == kRefined && score <= top.back().first) continue;
      // Near-copies of one cylinder would crowd the others out: a better one replaces its
      // copy, a worse one is dropped.
      const auto copy = std::find_if(top.begin(), top.end(), [&](const auto& t) { return alike(t.second, *c); });
      if (copy != top.end()) {
        if (score <= copy->first) continue;
        top.erase(copy);
      }
      top.emplace_back(score, *c);
      std::stable_sort(top.begin(), top.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
      if (top.size() > kRefined) top.pop_back();
    }
    // Each of the best few, refined, is a spar when asSpar passes it; the one the most
    // points then fit wins. (The best raw hypothesis can be a wrong one: on a
    // mast crossed by three scan lines, fatter cylinders hold more of the lines at first
    // and refine to nothing.)
    std::optional<Candidate> best;
    for (const auto& [score, hypothesis] : top) {
      // Refinement starts from the points within three bands: half a spar's worth there
      // at least (a sparse scan's rough normals give hypotheses few points fit closely).
      if (scoreOf(hypothesis, 3 * band) * stride < p.min_support / 2) continue;
      const Cylinder c = refineCylinder(pts, refineCylinder(pts, hypothesis, 3 * band), band);
      const std::optional<Candidate> k = asSpar(pts, c, p);
      if (k && (!best || k->on.size() > best->on.size())) best = k;
    }
    if (!best) break;
    const Cylinder c = best->cylinder;
    const std::vector<std::pair<double, double>>& on = best->on;
    const size_t first = best->first, last = best->last;
    const double min_arc = minArcDeg(c.radius, p), max_gap = sparRunGapM(c.radius, p.sensor_sigma_m);
    double lo = on[first].first, hi = on[last].first;
    // It runs on through the points of `length_from` on its surface (a sail cluster that
    // grew over the mast beside its luff) while each next two gaps' length of them starts
    // within a gap and goes round 0.4 of the arc the spar had to: two fans of a turntable
    // scanner (41-60° of a 9 cm mast 6 m away, 4-7 samples each) carry on a spar that
    // three of them showed, one fan (a line along one side) does not.
    std::vector<std::pair<double, double>> further;
    for (uint32_t i : length_from) {
      const Vec3& x = cloud.points[i];
      if (std::abs(radialResidual(x, c)) > band) continue;
      const AxialPosition a = axialPosition(x, c);
      if (a.along < lo || a.along > hi) further.emplace_back(a.along, a.angle);
    }
    for (size_t k = 0; k < on.size(); ++k)
      if (k < first || k > last) further.push_back(on[k]);
    auto extend = [&](double& end, double sign) {
      while (true) {
        std::vector<double> window;
        double reach = end, nearest = std::numeric_limits<double>::infinity();
        for (const auto& [along, a] : further) {
          const double beyond = sign * (along - end);
          if (beyond <= 0 || beyond > 2 * max_gap) continue;
          window.push_back(a);
          nearest = std::min(nearest, beyond);
          if (sign * (along - reach) > 0) reach = along;
        }
        if (window.empty() || nearest > max_gap || !goesRound(window, 0.4 * min_arc)) return;
        end = reach;
      }
    };
    extend(hi, 1.0);
    extend(lo, -1.0);
    SparFit fit;
    fit.found = true;
    fit.support = on.size();
    fit.rms_m = best->rms_m;
    fit.spar.name = "spar " + std::to_string(out.spars.size() + 1);
    fit.spar.axis = c.axis;
    fit.spar.base = c.point + lo * c.axis;
    fit.spar.length_m = hi - lo;
    fit.spar.radius_m = c.radius;
    // A stretch on the line of a spar found before, at its radius, is more of that spar:
    // its points had a gap (the sail or a spreader hid it, or a sparse scan missed it).
    std::vector<Vec3> surface;  // its own points, within its length
    for (size_t k = 0; k < on.size(); ++k)
      if (on[k].first >= lo && on[k].first <= hi) surface.push_back(pts[best->index[k]]);
    const auto earlier = std::find_if(out.spars.begin(), out.spars.end(),
                                      [&](const SparFit& f) { return onTheLineOf(f.spar, fit.spar); });
    if (earlier == out.spars.end()) {
      out.spars.push_back(fit);
      held.push_back(std::move(surface));
    } else {
      const size_t e = static_cast<size_t>(earlier - out.spars.begin());
      *earlier = mergeSpars(*earlier, held[e], fit, surface, band);
      held[e].insert(held[e].end(), surface.begin(), surface.end());
    }
    // The next spar is searched among the points this one does not hold.
    std::vector<uint32_t> rest;
    for (size_t k = 0; k < pool.size(); ++k)
      if (std::abs(distanceToSpar(pts[k], fit.spar)) > 3 * band) rest.push_back(pool[k]);
    pool = std::move(rest);
  }
  return out;
}

}  // namespace sailshape
