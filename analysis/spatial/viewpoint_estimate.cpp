#include "analysis/spatial/viewpoint_estimate.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "analysis/spatial/direction_map.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

// One patch: where it is, its plane's unit normal (either sign) and its
// measured density, log(samples per m²).
struct Patch {
  Vec3 p;
  Vec3 n;
  double log_density;
};

// Below these the model's logs run off to −∞ on samples that carry no
// information about v anyway: a patch seen edge-on, or straight overhead.
constexpr double kMinCosIncidence = 0.02;
constexpr double kMinCosElevation = 0.05;

// The model's log density at `patch` about `v`, less log Ω:
// log|n·(v − p)| − 2 log r − log r_h (see the header), with its gradient in v.
double modelLog(const Patch& patch, const Vec3& v, Vec3* gradient) {
  const Vec3 d = v - patch.p;
  const double r2 = std::max(d.squaredNorm(), 1e-12);
  const double r = std::sqrt(r2);
  const double dn = patch.n.dot(d);
  const double cos_inc = std::abs(dn) / r;
  const double h2 = d.x() * d.x() + d.y() * d.y();
  const double rh = std::sqrt(h2);
  const bool inc_floor = cos_inc < kMinCosIncidence;
  const bool elev_floor = rh < kMinCosElevation * r;
  // Clamped terms are written as the clamp times r, so their gradient stays that of r.
  const double inc_term = inc_floor ? std::log(kMinCosIncidence * r) : std::log(std::abs(dn));
  const double h_term = elev_floor ? std::log(kMinCosElevation * r) : std::log(rh);
  if (gradient) {
    Vec3 g = -2.0 * d / r2;
    g += inc_floor ? Vec3(d / r2) : Vec3(patch.n / dn);
    g -= elev_floor ? Vec3(d / r2) : Vec3(Vec3(d.x(), d.y(), 0) / h2);
    *gradient = g;
  }
  return inc_term - 2.0 * std::log(r) - h_term;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

// Each patch's residual about `v` before log Ω is taken off: modelLog − log ρ.
std::vector<double> residualsAt(const std::vector<Patch>& patches, const Vec3& v) {
  std::vector<double> a(patches.size());
  for (size_t i = 0; i < patches.size(); ++i) a[i] = modelLog(patches[i], v, nullptr) - patches[i].log_density;
  return a;
}

// The Cauchy objective Σ log(1 + ((a − log Ω)/scale)²) of residuals `a`.
double cauchyObjective(const std::vector<double>& a, double log_omega, double scale) {
  double f = 0;
  for (double x : a) {
    const double u = (x - log_omega) / scale;
    f += std::log1p(u * u);
  }
  return f;
}

// Robust spread of the residuals about `v` (log Ω taken as their median):
// the median absolute deviation, what the coarse search ranks positions by.
double madCost(const std::vector<Patch>& patches, const Vec3& v) {
  std::vector<double> a = residualsAt(patches, v);
  const double c = median(a);
  for (double& x : a) x = std::abs(x - c);
  return median(std::move(a));
}

struct Refined {
  Vec3 v;
  double log_omega = 0;
  double scale = 0;      // robust σ of the residuals, log units
  double objective = 0;  // Σ log(1 + (e/scale)²), at the scale of the best fit
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  bool ok = false;
};

// Cauchy-weighted Gauss–Newton (Levenberg damped) on (v, log Ω) from `start`, in
// three rounds, each with the residual scale re-read (robust σ) where the last
// ended: a start far off has a wide scale that would leave a near basin soft. A
// step moves v at most half way to the nearest patch: the scanner cannot pass
// through a surface it saw, and the model's |n·(v − p)| would let it.
Refined refine(const std::vector<Patch>& patches, const Vec3& start) {
  Refined out;
  out.v = start;
  const size_t n = patches.size();
  std::vector<double> a(n);
  std::vector<Vec3> g(n);
  auto residuals = [&](const Vec3& v) {
    for (size_t i = 0; i < n; ++i) a[i] = modelLog(patches[i], v, &g[i]) - patches[i].log_density;
  };
  auto nearestPatch = [&](const Vec3& v) {
    double d2 = std::numeric_limits<double>::infinity();
    for (const Patch& pa : patches) d2 = std::min(d2, (pa.p - v).squaredNorm());
    return std::sqrt(d2);
  };
  double c = 0;
  auto objective = [&](double cc) { return cauchyObjective(a, cc, out.scale); };
  // The Cauchy-weighted normal equations of (v, log Ω) at the residuals `a` (e = a − c):
  // J = [∇modelLog, −1] per patch, weight 1/(1 + (e/scale)²).
  Eigen::Matrix4d normal;
  Eigen::Vector4d rhs;
  double sum_w = 0, sum_we2 = 0;
  auto normalEquations = [&] {
    normal.setZero();
    rhs.setZero();
    sum_w = sum_we2 = 0;
    for (size_t i = 0; i < n; ++i) {
      const double e = a[i] - c;
      const double u = e / out.scale;
      const double w = 1.0 / (1.0 + u * u);
      Eigen::Vector4d j;
      j << g[i], -1.0;
      normal += w * j * j.transpose();
      rhs -= w * e * j;
      sum_w += w;
      sum_we2 += w * e * e;
    }
  };
  for (int round = 0; round < 3; ++round) {
    residuals(out.v);
    c = median(a);
    std::vector<double> dev(n);
    for (size_t i = 0; i < n; ++i) dev[i] = std::abs(a[i] - c);
    out.scale = std::max(1e-3, 1.4826 * median(std::move(dev)));
    double f = objective(c);
    double lambda = 1e-3;
    bool converged = false;
    for (int iter = 0; iter < 60 && !converged; ++iter) {
      normalEquations();
      const double max_step = 0.5 * nearestPatch(out.v);
      bool improved = false;
      for (int tries = 0; tries < 8 && !improved; ++tries) {
        Eigen::Matrix4d damped = normal;
        damped.diagonal() *= 1.0 + lambda;
        Eigen::Vector4d step = damped.ldlt().solve(rhs);
        if (!step.allFinite()) break;
        if (step.head<3>().norm() > max_step) step *= max_step / step.head<3>().norm();
        const Vec3 v_new = out.v + step.head<3>();
        const double c_new = c + step(3);
        residuals(v_new);
        const double f_new = objective(c_new);
        if (f_new < f) {
          improved = true;
          const double gain = f - f_new;
          out.v = v_new;
          c = c_new;
          f = f_new;
          lambda = std::max(1e-7, lambda / 3);
          converged = gain < 1e-9 * std::max(1.0, f);
        } else {
          lambda *= 10;
        }
      }
      if (!improved) {
        residuals(out.v);
        break;
      }
    }
  }
  residuals(out.v);
  // The covariance of (v, log Ω) at the optimum, Ω's row and column marginalised out.
  normalEquations();
  const double s2 = sum_we2 / std::max(1.0, sum_w - 4.0);
  Eigen::FullPivLU<Eigen::Matrix4d> lu(normal);
  if (!lu.isInvertible()) return out;
  out.cov = (s2 * lu.inverse()).topLeftCorner<3, 3>();
  out.log_omega = c;
  out.objective = objective(c);
  out.ok = out.v.allFinite() && out.cov.allFinite() && std::isfinite(c);
  return out;
}

// The area of the Voronoi cell about the origin among `others` (tangent-plane
// coordinates, m), or 0 when the neighbours given cannot bound it exactly: a cell
// whose farthest corner lies at D is fixed by the points within 2D, so it must
// reach no further than half the farthest neighbour. That refuses cells at the
// cloud's boundary (open on one side) and lattices too stretched for the count.
double voronoiArea(const std::vector<Eigen::Vector2d>& others) {
  double reach = 0;
  for (const Eigen::Vector2d& q : others) reach = std::max(reach, q.norm());
  if (!(reach > 0)) return 0;
  std::vector<Eigen::Vector2d> cell = {{-reach, -reach}, {reach, -reach}, {reach, reach}, {-reach, reach}};
  std::vector<Eigen::Vector2d> clipped;
  for (const Eigen::Vector2d& q : others) {
    const double q2 = q.squaredNorm();
    if (q2 < 1e-18) continue;  // a duplicate sample shares the cell
    // Keep x with x·q ≤ |q|²/2: the origin's side of the bisector.
    clipped.clear();
    for (size_t i = 0; i < cell.size(); ++i) {
      const Eigen::Vector2d& a = cell[i];
      const Eigen::Vector2d& b = cell[(i + 1) % cell.size()];
      const double fa = a.dot(q) - 0.5 * q2, fb = b.dot(q) - 0.5 * q2;
      if (fa <= 0) clipped.push_back(a);
      if ((fa < 0) != (fb < 0) && fa != fb) clipped.push_back(a + (b - a) * (fa / (fa - fb)));
    }
    cell.swap(clipped);
    if (cell.size() < 3) return 0;
  }
  double area = 0, far = 0;
  for (size_t i = 0; i < cell.size(); ++i) {
    const Eigen::Vector2d& a = cell[i];
    const Eigen::Vector2d& b = cell[(i + 1) % cell.size()];
    area += a.x() * b.y() - a.y() * b.x();
    far = std::max(far, a.norm());
  }
  return 2 * far <= reach ? 0.5 * std::abs(area) : 0;
}

// The patches: one per sampled point whose Voronoi cell on its neighbourhood's
// plane its neighbours bound; its density is one sample per cell area, right on
// a scan grid however stretched (a count over a disc reads a stretched grid low).
std::vector<Patch> samplePatches(const std::vector<Vec3>& points, const ViewpointEstimateParams& params) {
  const size_t k = params.k_neighbours;
  std::vector<Patch> patches;
  const std::unique_ptr<PointGrid> grid = gridForNeighbours(points, k);
  const size_t stride = std::max<size_t>(1, points.size() / params.max_patches);
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  std::vector<Eigen::Vector2d> tangent;
  for (size_t i = 0; i < points.size(); i += stride) {
    grid->nearest(points[i], k, idx, d2);
    if (idx.size() < k) continue;
    const PrincipalAxes plane = principalAxes(points, idx);
    const Vec3 normal = plane.axes.col(0), e1 = plane.axes.col(2), e2 = plane.axes.col(1);
    tangent.clear();
    for (uint32_t j : idx) {
      if (j == i) continue;
      const Vec3 q = points[j] - points[i];
      tangent.emplace_back(q.dot(e1), q.dot(e2));
    }
    const double area = voronoiArea(tangent);
    // Where samples lie a few noise σ apart the noise shuffles them across their
    // cells, and the cells that stay bounded are the small ones: such patches read
    // denser than they are.
    if (!(area > 0) || std::sqrt(area) < params.min_spacing_sigmas * params.sensor_sigma_m) continue;
    patches.push_back({points[i], normal, -std::log(area)});
  }
  return patches;
}

// Covariance of v from refits, each leaving out one of kBlocks groups of
// patches, the groups made of cells a third of the cloud's size wide.
Eigen::Matrix3d blockJackknife(const std::vector<Patch>& patches, const Vec3& v, double size) {
  constexpr int kBlocks = 8;
  const double cell = std::max(1e-6, size / 3.0);
  std::vector<std::vector<Patch>> leave_out(kBlocks);
  for (const Patch& pa : patches) {
    const Eigen::Vector3i c = (pa.p / cell).array().floor().cast<int>();
    const int block = static_cast<int>((static_cast<unsigned>(c.x()) * 73856093u ^ static_cast<unsigned>(c.y()) * 19349663u ^
                                        static_cast<unsigned>(c.z()) * 83492791u) %
                                       kBlocks);
    for (int b = 0; b < kBlocks; ++b)
      if (b != block) leave_out[b].push_back(pa);
  }
  std::vector<Vec3> fits;
  for (const std::vector<Patch>& kept : leave_out) {
    if (kept.size() == patches.size() || kept.size() < 50) continue;  // the block was empty, or all of it
    const Refined r = refine(kept, v);
    if (r.ok) fits.push_back(r.v);
  }
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  if (fits.size() < 2) return cov;
  Vec3 mean = Vec3::Zero();
  for (const Vec3& f : fits) mean += f;
  mean /= static_cast<double>(fits.size());
  for (const Vec3& f : fits) cov += (f - mean) * (f - mean).transpose();
  const double g = static_cast<double>(fits.size());
  return cov * (g - 1.0) / g;
}

// v refitted on the patches nearer than `mid` (their median range) from `v`, less v
// refitted on the farther ones (zero when either refit fails).
Vec3 rangeSplitDifference(const std::vector<Patch>& patches, const Vec3& v, double mid) {
  std::vector<Patch> near, far;
  for (const Patch& pa : patches) ((pa.p - v).norm() < mid ? near : far).push_back(pa);
  if (near.size() < 50 || far.size() < 50) return Vec3::Zero();
  const Refined a = refine(near, v), b = refine(far, v);
  return a.ok && b.ok ? Vec3(a.v - b.v) : Vec3::Zero();
}

// How many of (a sample of) `points` lie behind another sample seen from `v`
// in the same direction: a scanner sees the first surface along each beam only, so
// from where it stood none do but at depth edges; from the mirror image of that
// place through a surface (under a deck, behind a sail) the surfaces beyond the
// mirror stand in each other's way. Directions are binned on cells twice the
// beam's angular spacing (`omega`, sr per beam) wide; a sample is behind when it
// lies over 10 % (and 5 cm) further than the nearest in its cell or one beside it.
size_t samplesBehind(const std::vector<Vec3>& points, const Vec3& v, double omega) {
  const size_t stride = std::max<size_t>(1, points.size() / 20000);
  std::vector<Vec3> sample;
  for (size_t i = 0; i < points.size(); i += stride) sample.push_back(points[i]);
  const DirectionMap seen(sample, v, 2.0 * std::sqrt(std::max(omega, 1e-10)));
  size_t behind = 0;
  for (const Vec3& p : sample) {
    const Vec3 d = p - v;
    const double r = d.norm();
    if (!(r > 0)) continue;
    if (r > 1.1 * std::min(r, seen.nearest(d / r)) + 0.05) ++behind;
  }
  return behind;
}

}  // namespace

std::optional<ViewpointEstimate> estimateViewpoint(const Cloud& cloud, const ViewpointEstimateParams& params,
                                                   std::string* why) {
  auto refuse = [&](const std::string& reason) -> std::optional<ViewpointEstimate> {
    if (why) *why = reason;
    return std::nullopt;
  };
  if (cloud.size() < 10 * params.k_neighbours) return refuse("too few samples to read a density from");
  const std::vector<Patch> patches = samplePatches(cloud.points, params);
  if (patches.size() < 50) return refuse("too few patches whose neighbours bound their sample's cell");

  // Coarse search over a box three times the cloud's size, centred on it: the
  // scanner may stand well outside a cropped cloud.
  Vec3 lo = patches.front().p, hi = lo;
  for (const Patch& pa : patches) {
    lo = lo.cwiseMin(pa.p);
    hi = hi.cwiseMax(pa.p);
  }
  const double size = (hi - lo).maxCoeff();
  const Vec3 centre = 0.5 * (lo + hi);
  constexpr int kSteps = 11;
  struct Candidate {
    Vec3 v;
    double cost;
  };
  std::vector<Candidate> candidates;
  for (int ix = 0; ix < kSteps; ++ix)
    for (int iy = 0; iy < kSteps; ++iy)
      for (int iz = 0; iz < kSteps; ++iz) {
        const Vec3 f = Vec3(ix, iy, iz) / (kSteps - 1) - Vec3::Constant(0.5);
        const Vec3 v = centre + 1.5 * size * f;
        candidates.push_back({v, madCost(patches, v)});
      }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });

  // Refine the ten best starts that lie apart (the model has several basins).
  const double step = 1.5 * size / (kSteps - 1);
  std::vector<Refined> fits;
  std::vector<Vec3> starts;
  for (const Candidate& c : candidates) {
    if (starts.size() >= 10) break;
    bool near = false;
    for (const Vec3& s : starts) near = near || (s - c.v).norm() < 1.5 * step;
    if (near) continue;
    starts.push_back(c.v);
    Refined r = refine(patches, c.v);
    if (r.ok) fits.push_back(std::move(r));
  }
  if (fits.empty()) return refuse("the density model did not converge");
  // The density about a place and about its mirror image through a large surface
  // nearly agree, and the search may find only one of the two: refine the mirror
  // images of the best fit (the narrowest residuals) through the planes of the four
  // surfaces nearest it too, and again from a better fit one of those found.
  std::vector<Vec3> mirrored;
  for (int round = 0; round < 3; ++round) {
    const Vec3 v0 = std::min_element(fits.begin(), fits.end(), [](const Refined& x, const Refined& y) {
                      return x.scale < y.scale;
                    })->v;
    bool done = false;
    for (const Vec3& q : mirrored) done = done || (q - v0).norm() < 1e-6;
    if (done) break;
    mirrored.push_back(v0);
    std::vector<size_t> order(patches.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return (patches[a].p - v0).squaredNorm() < (patches[b].p - v0).squaredNorm();
    });
    std::vector<Vec3> mirrors;
    for (size_t j = 0; j < order.size() && mirrors.size() < 4; ++j) {
      const Patch& pa = patches[order[j]];
      const Vec3 m = v0 - 2.0 * pa.n.dot(v0 - pa.p) * pa.n;
      bool seen = (m - v0).norm() < 0.1 * (pa.p - v0).norm();
      for (const Vec3& q : mirrors) seen = seen || (q - m).norm() < 0.2 * (pa.p - v0).norm();
      if (seen) continue;
      mirrors.push_back(m);
      Refined r = refine(patches, m);
      if (r.ok) fits.push_back(std::move(r));
    }
  }
  // Objectives compared at one scale: that of the narrowest fit's residuals.
  const double scale = std::min_element(fits.begin(), fits.end(), [](const Refined& x, const Refined& y) {
                         return x.scale < y.scale;
                       })->scale;
  for (Refined& r : fits) r.objective = cauchyObjective(residualsAt(patches, r.v), r.log_omega, scale);
  std::sort(fits.begin(), fits.end(), [](const Refined& x, const Refined& y) { return x.objective < y.objective; });

  // Neighbourhoods overlap: each sample sits in about patches·k/N of them, so the
  // patches are that many times fewer independent measurements than they look.
  const double overlap =
      std::max(1.0, static_cast<double>(patches.size() * params.k_neighbours) / static_cast<double>(cloud.size()));
  // The Cauchy objective is a −2 log-likelihood up to a factor 2: fits within 9 of
  // the best (3σ), counted per independent measurement, the density tells apart no
  // better than a mirror image. Of those, the one that sees its samples unobstructed
  // stood there: no scanner sees through a deck. Two whose counts of samples behind
  // others differ by less than their Poisson 3σ are ambiguous.
  std::vector<size_t> likely;
  for (size_t i = 0; i < fits.size(); ++i)
    if (2.0 * (fits[i].objective - fits.front().objective) / overlap < 9.0) likely.push_back(i);
  // One beam spacing for every candidate, the best density fit's: a far candidate's
  // own would be as small as the scene looks from there, and hide nothing.
  const double omega = std::exp(fits.front().log_omega);
  std::vector<double> behind(fits.size(), 0.0);
  for (size_t i : likely) behind[i] = static_cast<double>(samplesBehind(cloud.points, fits[i].v, omega));
  size_t chosen = likely.front();
  for (size_t i : likely)
    if (behind[i] < behind[chosen] ||
        (behind[i] == behind[chosen] && fits[i].objective < fits[chosen].objective))
      chosen = i;
  const Refined& best = fits[chosen];
  bool ambiguous = false;
  for (size_t i : likely) {
    const bool far = (fits[i].v - best.v).norm() > 0.05 * (best.v - centre).norm() + 0.1;
    if (i != chosen && far && behind[i] - behind[chosen] < 3.0 * std::sqrt(behind[i] + behind[chosen] + 1.0))
      ambiguous = true;
  }

  ViewpointEstimate e;
  e.position = best.v;
  // The fit's covariance knows the density's noise, not where the model departs
  // from the scan (cells jittered by noise near the unit, where the samples lie as
  // close as the noise): those errors are shared by neighbouring patches. A jackknife over
  // spatial blocks sees them, and joins the fit's.
  const Eigen::Matrix3d jack = blockJackknife(patches, best.v, size);
  // Where the model's bias grows with range (samples as close as the noise near the
  // unit, cells stretched far from it) the near and the far patches disagree on
  // where the unit stood; half their difference joins the σ.
  std::vector<double> ranges;
  for (const Patch& pa : patches) ranges.push_back((pa.p - best.v).norm());
  e.median_range_m = median(ranges);
  const Vec3 split = rangeSplitDifference(patches, best.v, e.median_range_m);
  e.sigma_m = ((overlap * best.cov.diagonal()).cwiseMax(0.0) + jack.diagonal().cwiseMax(0.0) + 0.25 * split.cwiseAbs2())
                  .cwiseSqrt();
  e.beam_solid_angle_sr = std::exp(best.log_omega);
  e.log_density_scatter = best.scale;
  e.patches = patches.size();
  e.mirror_ambiguous = ambiguous;
  if (!(e.sigma_m.norm() <= params.max_relative_sigma * e.median_range_m)) {
    char detail[200];
    std::snprintf(detail, sizeof detail, ": its best fit, (%.2f, %.2f, %.2f) m, is uncertain by %.2f m at %.2f m range",
                  e.position.x(), e.position.y(), e.position.z(), e.sigma_m.norm(), e.median_range_m);
    return refuse("the samples' density does not tell where the scanner stood (an evenly sampled cloud?)" +
                  std::string(detail));
  }
  return e;
}

}  // namespace sailshape
