#include "analysis/surface/smoothing.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "analysis/core/errors.hpp"
#include "analysis/core/fit.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/spatial/principal_axes.hpp"

namespace sailshape {
namespace {

// A local MLS surface: frame (origin, eu, ev, normal) and the height
// c0 + c1 u + c2 v + c3 u² + c4 uv + c5 v² over (u, v) in units of `scale`.
struct LocalSurface {
  Vec3 origin = Vec3::Zero(), eu = Vec3::UnitX(), ev = Vec3::UnitY(), normal = Vec3::UnitZ();
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  double scale = 1;  // 1 / neighbourhood radius
  // How far the neighbours' weighted centroid lies from the fitted point along the
  // surface, in neighbourhood radii: ~0 inside the surface, ~0.4 on a straight edge.
  double centroid_offset = 0;

  Vec3 project(const Vec3& p) const {
    const Vec3 d = p - origin;
    const double u = d.dot(eu), v = d.dot(ev);
    const double us = u * scale, vs = v * scale;
    const double h = c[0] + c[1] * us + c[2] * vs + c[3] * us * us + c[4] * us * vs + c[5] * vs * vs;
    return origin + u * eu + v * ev + h * normal;
  }
};

// exp(x) for x in [-2, 0] (the weights' range) to ~1e-12 relative: exp(x/4) by
// its Taylor series to x⁸, squared twice. Plain arithmetic the compiler can
// vectorise, several times cheaper than std::exp.
inline double expWeight(double x) {
  const double t = 0.25 * x;
  double e = 1.0 / 40320;
  for (double c : {1.0 / 5040, 1.0 / 720, 1.0 / 120, 1.0 / 24, 1.0 / 6, 0.5, 1.0, 1.0}) e = e * t + c;
  e *= e;
  return e * e;
}

// The fits' sums run over pairs of rows at once (two lanes of a 16-byte vector,
// plain SSE2), each lane summing every other row: the same result every run.
typedef double Lanes __attribute__((vector_size(16)));
inline Lanes load2(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Lanes both(double x) { return Lanes{x, x}; }
inline double sum(Lanes v) { return v[0] + v[1]; }

// A fit's rows: coordinates apart (x, y, z) and their squared distances from the fitted point.
struct Rows {
  std::vector<double> x, y, z, d2;
  size_t size() const { return x.size(); }
  void resize(size_t n) {
    x.resize(n);
    y.resize(n);
    z.resize(n);
    d2.resize(n);
  }
};

// The weighted plane through the rows `r` (none beyond the radius² h2) around the
// point `at`; their weights go to w.
LocalSurface fitPlane(const Rows& r, const Vec3& at, double h2, std::vector<double>& w) {
  LocalSurface s;
  const size_t k = r.size();
  h2 = std::max(1e-12, h2);
  w.resize(k);
  const double g = -2.0 / h2;  // the radius is 2σ of the weights
  for (size_t j = 0; j < k; ++j) w[j] = expWeight(std::max(-2.0, g * r.d2[j]));
  // Moments about `at` (small numbers: no cancellation in the covariance).
  const Lanes ax = both(at.x()), ay = both(at.y()), az = both(at.z());
  Lanes vw = both(0), vx = vw, vy = vw, vz = vw, vxx = vw, vxy = vw, vxz = vw, vyy = vw, vyz = vw, vzz = vw;
  size_t j = 0;
  for (; j + 2 <= k; j += 2) {
    const Lanes x = load2(&r.x[j]) - ax, y = load2(&r.y[j]) - ay, z = load2(&r.z[j]) - az, wj = load2(&w[j]);
    const Lanes wx = wj * x, wy = wj * y, wz = wj * z;
    vw += wj;
    vx += wx;
    vy += wy;
    vz += wz;
    vxx += wx * x;
    vxy += wx * y;
    vxz += wx * z;
    vyy += wy * y;
    vyz += wy * z;
    vzz += wz * z;
  }
  double sw = sum(vw), sx = sum(vx), sy = sum(vy), sz = sum(vz), sxx = sum(vxx), sxy = sum(vxy), sxz = sum(vxz),
         syy = sum(vyy), syz = sum(vyz), szz = sum(vzz);
  for (; j < k; ++j) {
    const double x = r.x[j] - at.x(), y = r.y[j] - at.y(), z = r.z[j] - at.z(), wj = w[j];
    sw += wj;
    sx += wj * x;
    sy += wj * y;
    sz += wj * z;
    sxx += wj * x * x;
    sxy += wj * x * y;
    sxz += wj * x * z;
    syy += wj * y * y;
    syz += wj * y * z;
    szz += wj * z * z;
  }
  const Vec3 m(sx / sw, sy / sw, sz / sw);
  Eigen::Matrix3d cov;
  cov(0, 0) = sxx - sw * m.x() * m.x();
  cov(0, 1) = cov(1, 0) = sxy - sw * m.x() * m.y();
  cov(0, 2) = cov(2, 0) = sxz - sw * m.x() * m.z();
  cov(1, 1) = syy - sw * m.y() * m.y();
  cov(1, 2) = cov(2, 1) = syz - sw * m.y() * m.z();
  cov(2, 2) = szz - sw * m.z() * m.z();
  const Vec3 mean = at + m;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);
  s.normal = eig.eigenvectors().col(0);
  s.eu = eig.eigenvectors().col(2);
  s.ev = s.normal.cross(s.eu);
  s.origin = at - s.normal * s.normal.dot(at - mean);
  s.centroid_offset = (mean - s.origin).norm() / std::sqrt(h2);
  s.scale = 1.0 / std::sqrt(h2);
  return s;
}

// The weighted quadratic height field over the plane `s` (from fitPlane, with the
// same rows and their weights w).
void fitQuadratic(LocalSurface& s, const Rows& r, const std::vector<double>& w) {
  // The normal equations need the weighted moments of u^a v^b up to a + b = 4
  // and of z u^a v^b up to a + b = 2: M[0..14] and Z[0..5] below.
  const size_t k = r.size();
  const Vec3 eu = s.eu * s.scale, ev = s.ev * s.scale;
  Lanes L[21];
  for (Lanes& l : L) l = both(0);
  auto add = [&](Lanes wj, Lanes u, Lanes v, Lanes z) {
    const Lanes uu = u * u, uv = u * v, vv = v * v;
    const Lanes wu = wj * u, wv = wj * v, wuu = wj * uu, wuv = wj * uv, wvv = wj * vv;
    L[0] += wj;
    L[1] += wu;
    L[2] += wv;
    L[3] += wuu;
    L[4] += wuv;
    L[5] += wvv;
    L[6] += wuu * u;    // u³
    L[7] += wuu * v;    // u²v
    L[8] += wvv * u;    // uv²
    L[9] += wvv * v;    // v³
    L[10] += wuu * uu;  // u⁴
    L[11] += wuu * uv;  // u³v
    L[12] += wuu * vv;  // u²v²
    L[13] += wuv * vv;  // uv³
    L[14] += wvv * vv;  // v⁴
    L[15] += wj * z;
    L[16] += wu * z;
    L[17] += wv * z;
    L[18] += wuu * z;
    L[19] += wuv * z;
    L[20] += wvv * z;
  };
  const Lanes ox = both(s.origin.x()), oy = both(s.origin.y()), oz = both(s.origin.z());
  const Lanes eux = both(eu.x()), euy = both(eu.y()), euz = both(eu.z());
  const Lanes evx = both(ev.x()), evy = both(ev.y()), evz = both(ev.z());
  const Lanes nx = both(s.normal.x()), ny = both(s.normal.y()), nz = both(s.normal.z());
  size_t j = 0;
  for (; j + 2 <= k; j += 2) {
    const Lanes dx = load2(&r.x[j]) - ox, dy = load2(&r.y[j]) - oy, dz = load2(&r.z[j]) - oz;
    add(load2(&w[j]), dx * eux + dy * euy + dz * euz, dx * evx + dy * evy + dz * evz, dx * nx + dy * ny + dz * nz);
  }
  double M[21];
  for (int i = 0; i < 21; ++i) M[i] = sum(L[i]);
  if (j < k) {  // the odd row in lane 0 of a last pass
    for (Lanes& l : L) l = both(0);
    const double dx = r.x[j] - s.origin.x(), dy = r.y[j] - s.origin.y(), dz = r.z[j] - s.origin.z();
    add(Lanes{w[j], 0}, Lanes{dx * eu.x() + dy * eu.y() + dz * eu.z(), 0},
        Lanes{dx * ev.x() + dy * ev.y() + dz * ev.z(), 0},
        Lanes{dx * s.normal.x() + dy * s.normal.y() + dz * s.normal.z(), 0});
    for (int i = 0; i < 21; ++i) M[i] += L[i][0];
  }
  QuadraticHeightField field = QuadraticHeightField::fromMoments(M, M + 15);
  if (field.solve()) s.c = field.coeffs;
}

// Anchored MLS: an anchor whose neighbours' centroid lies within this many radii
// of it along the surface, and whose neighbourhood needed at most this many
// radii, has the surface all around it (a straight edge puts the centroid 0.42
// radii off; random sampling of ~200 points, about 0.05).
constexpr double kInsideCentroidOffset = 0.12;
constexpr double kInsideRadius = 1.25;

// One anchor per cubic cell of side `cell`: the point nearest the cell's centroid.
std::vector<uint32_t> pickAnchors(const std::vector<Vec3>& pts, double cell) {
  KeyIds ids(pts.size() / 4);
  std::vector<uint32_t> cell_of(pts.size());
  std::vector<Vec3> sum;
  std::vector<uint32_t> count;
  for (size_t i = 0; i < pts.size(); ++i) {
    const uint32_t c = ids.idOf(voxelKey(pts[i], cell));
    if (c == sum.size()) {
      sum.push_back(Vec3::Zero());
      count.push_back(0);
    }
    sum[c] += pts[i];
    ++count[c];
    cell_of[i] = c;
  }
  std::vector<uint32_t> best(sum.size(), 0);
  std::vector<double> best_d2(sum.size(), std::numeric_limits<double>::infinity());
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const uint32_t c = cell_of[i];
    const double d2 = (pts[i] - sum[c] / count[c]).squaredNorm();
    if (d2 < best_d2[c]) {
      best_d2[c] = d2;
      best[c] = i;
    }
  }
  std::sort(best.begin(), best.end());
  return best;
}

// Fewest neighbours a clean cloud brings k down to: a quadratic's six
// coefficients from a few dozen points.
constexpr size_t kMinAdaptedK = 40;
// The sail max_radius_ratio was set on: √ of the 10 m example mainsail's 18 m².
constexpr double kReferenceSailSize = 4.25;

// The cloud's noise: at up to `samples` points spread through it, the RMS distance
// of its 24 nearest from the quadratic height field fitted to them over their
// plane (scaled by √(24 / 18) for the fit's six coefficients); the median (m).
double measuredNoise(const std::vector<Vec3>& pts, const PointGrid& grid, size_t samples = 256) {
  constexpr size_t k0 = 24;
  if (pts.size() < k0) return 0;
  std::vector<uint32_t> idx;
  std::vector<double> d2, rms;
  const size_t stride = std::max<size_t>(1, pts.size() / samples);
  for (size_t i = 0; i < pts.size(); i += stride) {
    grid.nearest(pts[i], k0, idx, d2);
    const HeightFieldSpread f = quadraticHeightFieldSpread(pts, idx, principalAxes(pts, idx));
    rms.push_back(std::sqrt(f.residual_ss_m2 / static_cast<double>(f.points - 6)));
  }
  std::nth_element(rms.begin(), rms.begin() + rms.size() / 2, rms.end());
  return rms[rms.size() / 2];
}

void checkSmoothingParams(const Cloud& cloud, const SmoothingParams& p) {
  if (p.k_neighbours < 6 || p.k_neighbours > 256)
    throw InvalidInput("[smoothMls] k_neighbours must be in [6, 256] (got " + std::to_string(p.k_neighbours) + ")");
  if (p.polynomial_order != 1 && p.polynomial_order != 2)
    throw InvalidInput("[smoothMls] polynomial_order must be 1 or 2 (got " + std::to_string(p.polynomial_order) + ")");
  if (!(p.good_m > 0) || !(p.fair_m >= p.good_m))
    throw InvalidInput("[smoothMls] need 0 < good_m <= fair_m (got " + std::to_string(p.good_m) + ", " +
                       std::to_string(p.fair_m) + ")");
  if (!(p.anchor_ratio >= 0 && p.anchor_ratio <= 1))
    throw InvalidInput("[smoothMls] anchor_ratio must be in [0, 1] (got " + std::to_string(p.anchor_ratio) + ")");
  if (!(p.max_radius_ratio >= 0))
    throw InvalidInput("[smoothMls] max_radius_ratio must be >= 0 (got " + std::to_string(p.max_radius_ratio) + ")");
  if (!(p.reference_density_per_m2 >= 0))
    throw InvalidInput("[smoothMls] reference_density_per_m2 must be >= 0 (got " +
                       std::to_string(p.reference_density_per_m2) + ")");
  const size_t k = static_cast<size_t>(p.k_neighbours);
  if (cloud.size() < k)
    throw InvalidInput("[smoothMls] cloud has " + std::to_string(cloud.size()) + " points, fewer than k_neighbours = " +
                       std::to_string(k));
}

// The neighbourhood every fit takes: k points, within about `radius` (m) in the
// cloud's body; and the cloud's noise as measured (m, 0 when not measured).
struct Neighbourhood {
  size_t k = 0;
  double radius = 0;
  double measured_noise_m = 0;
};

// The neighbourhood for the cloud `pts`: k_neighbours, more in a dense cloud, fewer
// where the radius would outgrow the sail or the cloud is cleaner than the sensor.
Neighbourhood chooseNeighbourhood(const std::vector<Vec3>& pts, const SmoothingParams& p) {
  Neighbourhood nb;
  size_t k = static_cast<size_t>(p.k_neighbours);
  // The neighbourhood radius: the median k-th neighbour distance over a sample of points.
  // One grid serves both medians: its searches are exact at any cell width.
  const std::unique_ptr<PointGrid> median_grid = gridForNeighbours(pts, k);
  auto radiusFor = [&](size_t neighbours) {
    return std::max(1e-6, medianNeighbourDistance(*median_grid, pts, neighbours, 256));
  };
  double radius = radiusFor(k);
  const double density = static_cast<double>(k) / (M_PI * radius * radius);  // points/m² on the surface
  if (p.reference_density_per_m2 > 0 && density > p.reference_density_per_m2) {
    k = std::min(pts.size(), static_cast<size_t>(std::lround(static_cast<double>(k) *
                                                             std::sqrt(density / p.reference_density_per_m2))));
    radius = radiusFor(k);
  }
  // Fewer neighbours, k × factor but not under kMinAdaptedK; never more than now.
  auto takeFewer = [&](double factor) {
    const size_t fewer = std::max<size_t>(kMinAdaptedK, std::lround(static_cast<double>(k) * factor));
    if (fewer < k) {
      k = std::min(fewer, pts.size());
      radius = radiusFor(k);
    }
  };
  if (p.adapt_to_noise || p.max_radius_ratio > 0) nb.measured_noise_m = measuredNoise(pts, *median_grid);
  if (p.max_radius_ratio > 0) {
    const double sail_size = std::sqrt(static_cast<double>(pts.size()) / density);
    // Noisier for its size than 4 mm on the reference sail, the averaging is worth a
    // wider patch: the best radius grows as (noise / size)^0.2 (the quadratic's
    // bias grows as radius⁴, the noise left falls as 1 / radius).
    const double relative_noise = (nb.measured_noise_m / sail_size) / (p.good_m / kReferenceSailSize);
    const double max_radius = p.max_radius_ratio * std::pow(std::max(1.0, relative_noise), 0.2) * sail_size;
    if (radius > max_radius) takeFewer((max_radius / radius) * (max_radius / radius));
  }
  if (p.adapt_to_noise) {
    const double ratio = nb.measured_noise_m / (0.5 * p.good_m);
    if (ratio < 1) takeFewer(std::sqrt(std::max(0.0, ratio)));
  }
  nb.k = k;
  nb.radius = radius;
  return nb;
}

// Points with their coordinates apart (x, y, z: the distance loop vectorises).
struct Soa {
  std::vector<double> x, y, z;
  void assign(const std::vector<Vec3>& p) {
    x.resize(p.size());
    y.resize(p.size());
    z.resize(p.size());
    for (size_t j = 0; j < p.size(); ++j) {
      x[j] = p[j].x();
      y[j] = p[j].y();
      z[j] = p[j].z();
    }
  }
  // Squared distances from `at` into d2.
  void distances(const Vec3& at, std::vector<double>& d2) const {
    const size_t m = x.size();
    d2.resize(m);
    const double ax = at.x(), ay = at.y(), az = at.z();
    const double *px = x.data(), *py = y.data(), *pz = z.data();
    double* out = d2.data();
    for (size_t j = 0; j < m; ++j)
      out[j] = (px[j] - ax) * (px[j] - ax) + (py[j] - ay) * (py[j] - ay) + (pz[j] - az) * (pz[j] - az);
  }
};

// The points every query in one grid cell reads (PointGrid::cellNeighbourhood),
// gathered once per cell.
struct Gathered {
  size_t cell = 0;
  Soa near;
  // The cells within two reaches, gathered at the cell's first edge refit.
  bool has_wide = false;
  Soa wide;
  std::vector<uint32_t> index;
  std::vector<Vec3> points;
  void gather(const PointGrid& g, size_t c, double r) {
    cell = c;
    has_wide = false;
    g.cellNeighbourhood(c, r, index, points);
    near.assign(points);
  }
};

// One thread's scratch for its fits.
struct Buffers {
  std::vector<double> d2, part_d2;
  std::vector<uint32_t> part, rows, idx;
  std::vector<uint8_t> bin;
  Rows rows_fit;
  std::vector<double> w;
};

// The local surfaces of one cloud: at any point, the points within the radius, or
// the k nearest where the radius holds fewer than k (an edge, a sparse patch).
// Every fit goes cell by cell of grid() and reads the points every query in its
// cell reads, gathered once per cell (Gathered). Rows are taken in the gathering's
// order, so a point's fit is the same whichever path fits it.
class LocalFits {
 public:
  LocalFits(const std::vector<Vec3>& pts, const Neighbourhood& nb, int polynomial_order)
      : pts_(pts),
        k_(nb.k),
        // At an edge the neighbourhood is one-sided: k points reach only about 1.4
        // radii into the surface, and the quadratic's slope at the edge, which the
        // entry and exit angles read, is several times noisier than inside (degrees
        // under 4 mm noise). There the fit is made again from the 2k nearest, which
        // reach about as far into the surface as an inner neighbourhood spans across it.
        k_edge_(std::min(2 * nb.k, pts.size())),
        // Gathered from a grid a little wider than the radius, so the k nearest of
        // most points whose radius holds fewer than k are among the candidates too.
        reach_(1.3 * nb.radius),
        grid_(pts, reach_),
        r2_(nb.radius * nb.radius),
        reach2_(reach_ * reach_),
        wide_reach_(2.0 * reach_),
        // Rings of cells the wide gathering covers around its cell, as PointGrid counts them.
        wide_rings_(std::ceil(wide_reach_ * (1.0 / grid_.cellSize()))),
        polynomial_order_(polynomial_order) {}

  const PointGrid& grid() const { return grid_; }
  double reach() const { return reach_; }

  // The local surface at `at`, from the points gathered for its cell `g` (or
  // further when they do not hold enough); the neighbourhood radius used (m) goes
  // to *used_radius.
  LocalSurface fitAt(const Vec3& at, Buffers& b, float* used_radius, Gathered& g) const {
    g.near.distances(at, b.d2);
    within(b.d2, r2_, b.rows);
    double h2 = r2_;
    if (b.rows.size() >= k_) {
      takeRows(g.near, b.d2, b.rows, b);
    } else {
      // The k nearest by (distance², slot): within reach from the cell's
      // gathering, else from the wider one, else a search.
      h2 = selectNearest(b.d2, reach2_, k_, b.bin, b.part, b.part_d2, b.rows);
      if (h2 >= 0)
        takeRows(g.near, b.d2, b.rows, b);
      else
        h2 = nearestFromWide(at, k_, std::numeric_limits<double>::infinity(), b, g);
    }
    LocalSurface fit = fitPlane(b.rows_fit, at, h2, b.w);
    if (fit.centroid_offset > kInsideCentroidOffset && k_edge_ > b.rows_fit.size()) {
      // Twice the points lie within about √2 the radius that held k (1.6 leaves room
      // for a density falling off towards the edge); further out only if not.
      h2 = nearestFromWide(at, k_edge_, 2.56 * h2, b, g);
      fit = fitPlane(b.rows_fit, at, h2, b.w);
    }
    if (polynomial_order_ == 2) fitQuadratic(fit, b.rows_fit, b.w);
    *used_radius = static_cast<float>(std::sqrt(h2));
    return fit;
  }

 private:
  // Slots j of `d2` with d2[j] <= limit2 into sel (branch-free: every slot written, kept when within).
  static void within(const std::vector<double>& d2, double limit2, std::vector<uint32_t>& sel) {
    const size_t m = d2.size();
    sel.resize(m);
    size_t o = 0;
    for (size_t j = 0; j < m; ++j) {
      sel[o] = static_cast<uint32_t>(j);
      o += d2[j] <= limit2 ? 1 : 0;
    }
    sel.resize(o);
  }
  // Rows (points and distance²) of the slots `rows` of gathering `from`.
  static void takeRows(const Soa& from, const std::vector<double>& d2, const std::vector<uint32_t>& rows,
                       Buffers& b) {
    b.rows_fit.resize(rows.size());
    for (size_t j = 0; j < rows.size(); ++j) {
      b.rows_fit.x[j] = from.x[rows[j]];
      b.rows_fit.y[j] = from.y[rows[j]];
      b.rows_fit.z[j] = from.z[rows[j]];
      b.rows_fit.d2[j] = d2[rows[j]];
    }
  }
  // Rows from a search of the grid (the gathering did not hold enough): the n
  // nearest sorted by (distance², index); returns the n-th distance².
  double nearestRows(const Vec3& at, size_t count, Buffers& b) const {
    grid_.nearest(at, count, b.idx, b.part_d2);
    b.rows_fit.resize(b.idx.size());
    for (size_t j = 0; j < b.idx.size(); ++j) {
      b.rows_fit.x[j] = pts_[b.idx[j]].x();
      b.rows_fit.y[j] = pts_[b.idx[j]].y();
      b.rows_fit.z[j] = pts_[b.idx[j]].z();
      b.rows_fit.d2[j] = b.part_d2[j];
    }
    return b.rows_fit.d2.back();
  }
  // The wide gathering of g's cell (gathered at its first use) and how far around
  // `at` it surely holds every point, squared.
  double wideSure2(const Vec3& at, Gathered& g) const {
    if (!g.has_wide) {
      grid_.cellNeighbourhood(g.cell, wide_reach_, g.index, g.points);
      g.wide.assign(g.points);
      g.has_wide = true;
    }
    if (g.wide.x.size() >= pts_.size()) return std::numeric_limits<double>::infinity();
    const double cell = grid_.cellSize();
    const double margin =
        std::max(0.0, 0.5 * cell - (at - grid_.cellCentre(g.cell)).cwiseAbs().maxCoeff() - 1e-9 * cell);
    const double sure = wide_rings_ * cell + margin;
    return sure * sure;
  }
  // Rows: the `count` nearest of `at` within limit2 from the wide gathering (rows
  // and distance² of the k-th), else from a search.
  double nearestFromWide(const Vec3& at, size_t count, double limit2, Buffers& b, Gathered& g) const {
    limit2 = std::min(limit2, wideSure2(at, g));
    g.wide.distances(at, b.d2);
    const double h2 = selectNearest(b.d2, limit2, count, b.bin, b.part, b.part_d2, b.rows);
    if (h2 < 0) return nearestRows(at, count, b);
    takeRows(g.wide, b.d2, b.rows, b);
    return h2;
  }

  const std::vector<Vec3>& pts_;
  const size_t k_, k_edge_;
  const double reach_;
  const PointGrid grid_;
  const double r2_, reach2_, wide_reach_, wide_rings_;
  const int polynomial_order_;
};

// Plain MLS: every point projected onto its own local surface, into `out`; each
// point's neighbourhood radius (m) into point_radius.
void projectEveryPoint(const LocalFits& fits, const std::vector<Vec3>& pts, std::vector<Vec3>& out,
                       std::vector<float>& point_radius) {
  const PointGrid& grid = fits.grid();
  const size_t cells = grid.cellCount();
  const std::vector<uint32_t>& cell_start = grid.cellStart();
  const std::vector<uint32_t>& cell_points = grid.cellPoints();
#pragma omp parallel
  {
    Buffers b;
    Gathered near;
#pragma omp for schedule(dynamic, 4)
    for (long c = 0; c < static_cast<long>(cells); ++c) {
      const size_t cs = static_cast<size_t>(c);
      near.gather(grid, cs, fits.reach());
      for (uint32_t slot = cell_start[cs]; slot < cell_start[cs + 1]; ++slot) {
        const uint32_t i = cell_points[slot];
        out[i] = fits.fitAt(pts[i], b, &point_radius[i], near).project(pts[i]);
      }
    }
  }
}

// The local surfaces at the anchors (indices into pts), fitted cell by cell of
// the fits' grid, and each one's neighbourhood radius (m).
struct AnchorSurfaces {
  std::vector<LocalSurface> surfaces;
  std::vector<float> radius;
};

AnchorSurfaces fitAnchors(const LocalFits& fits, const std::vector<Vec3>& pts, const std::vector<uint32_t>& anchors) {
  const PointGrid& grid = fits.grid();
  const size_t cells = grid.cellCount();
  const std::vector<uint32_t>& cell_start = grid.cellStart();
  const std::vector<uint32_t>& cell_points = grid.cellPoints();
  AnchorSurfaces a;
  a.surfaces.resize(anchors.size());
  a.radius.resize(anchors.size());
  // Anchors grouped by grid cell (counting sort), fitted cell by cell.
  std::vector<uint32_t> cell_of(pts.size());
  for (size_t c = 0; c < cells; ++c)
    for (uint32_t slot = cell_start[c]; slot < cell_start[c + 1]; ++slot)
      cell_of[cell_points[slot]] = static_cast<uint32_t>(c);
  std::vector<uint32_t> anchor_start(cells + 1, 0), by_cell(anchors.size());
  for (uint32_t i : anchors) ++anchor_start[cell_of[i] + 1];
  for (size_t c = 0; c < cells; ++c) anchor_start[c + 1] += anchor_start[c];
  {
    std::vector<uint32_t> fill(anchor_start.begin(), anchor_start.end() - 1);
    for (uint32_t k = 0; k < anchors.size(); ++k) by_cell[fill[cell_of[anchors[k]]]++] = k;
  }
#pragma omp parallel
  {
    Buffers b;
    Gathered near;
#pragma omp for schedule(dynamic, 4)
    for (long c = 0; c < static_cast<long>(cells); ++c) {
      const size_t cs = static_cast<size_t>(c);
      if (anchor_start[cs] == anchor_start[cs + 1]) continue;
      near.gather(grid, cs, fits.reach());
      for (uint32_t s = anchor_start[cs]; s < anchor_start[cs + 1]; ++s) {
        const uint32_t k = by_cell[s];
        a.surfaces[k] = fits.fitAt(pts[anchors[k]], b, &a.radius[k], near);
      }
    }
  }
  return a;
}

// Anchored MLS: local surfaces at anchors about anchor_ratio × radius apart; each
// point is projected onto a blend of its nearest anchors' surfaces where they are
// all inside the surface, onto its own fit otherwise. Projections go to `out`,
// neighbourhood radii (m) to point_radius. Returns the local surfaces fitted.
size_t projectAnchored(const LocalFits& fits, const std::vector<Vec3>& pts, double anchor_ratio, double radius,
                       const Progress& progress, std::vector<Vec3>& out, std::vector<float>& point_radius) {
  const PointGrid& grid = fits.grid();
  const size_t cells = grid.cellCount();
  const std::vector<uint32_t>& cell_start = grid.cellStart();
  const std::vector<uint32_t>& cell_points = grid.cellPoints();
  const std::vector<uint32_t> anchors = pickAnchors(pts, std::max(1e-6, anchor_ratio * radius));
  const AnchorSurfaces fitted = fitAnchors(fits, pts, anchors);
  const std::vector<LocalSurface>& surfaces = fitted.surfaces;
  const std::vector<float>& anchor_radius = fitted.radius;
  progress("smoothing", 0.5);
  // An anchor inside the surface (its neighbourhood all around it, within the
  // radius) stands for the points near it; near an edge, where the
  // neighbourhood turns one-sided and each point's own fit differs most from
  // its neighbour's, every point gets its own fit as in plain MLS.
  std::vector<char> inside(anchors.size());
  for (size_t a = 0; a < anchors.size(); ++a)
    inside[a] = surfaces[a].centroid_offset <= kInsideCentroidOffset && anchor_radius[a] <= kInsideRadius * radius;
  std::vector<Vec3> anchor_pts(anchors.size());
  for (size_t a = 0; a < anchors.size(); ++a) anchor_pts[a] = pts[anchors[a]];
  const double spacing = std::max(1e-6, anchor_ratio * radius);
  const PointGrid anchor_grid(anchor_pts, spacing);
  const size_t blend = std::min<size_t>(4, anchors.size());
  std::vector<char> own_fit(pts.size(), 0);
  // The points go cell by cell of `grid`: a cell's points share the anchors
  // within `sure` of any of them, gathered once. A point whose `blend`-th
  // nearest of those lies within `sure` has its nearest anchors among them
  // (the same ones and order a search gives: ties to the lower index);
  // otherwise (far from every anchor) it searches.
  const double sure = 2.0 * spacing;
  const double gather = (0.5 * std::sqrt(3.0) * grid.cellSize() + sure) * (1 + 1e-9);
  // One parallel loop over the cells: its per-point body is the hot path.
#pragma omp parallel
  {
    Buffers b;
    Gathered near_points;
    std::vector<uint32_t> near, shared;
    std::vector<double> nd2, shared_d2;
    std::pair<double, uint32_t> top[4];  // blend <= 4
#pragma omp for schedule(dynamic, 4)
    for (long c = 0; c < static_cast<long>(cells); ++c) {
      const size_t cs = static_cast<size_t>(c);
      bool gathered = false;  // near_points holds this cell's neighbourhood
      anchor_grid.withinRadius(grid.cellCentre(cs), gather, shared, shared_d2);
      for (uint32_t slot = cell_start[cs]; slot < cell_start[cs + 1]; ++slot) {
        const uint32_t i = cell_points[slot];
        // The `blend` nearest gathered anchors by (distance², index), as a search orders them.
        size_t have = 0;
        for (uint32_t a : shared) {
          const std::pair<double, uint32_t> cand((anchor_pts[a] - pts[i]).squaredNorm(), a);
          if (have == blend && !(cand < top[blend - 1])) continue;
          size_t j = have < blend ? have++ : blend - 1;
          for (; j > 0 && cand < top[j - 1]; --j) top[j] = top[j - 1];
          top[j] = cand;
        }
        if (have == blend && top[blend - 1].first <= sure * sure) {
          near.resize(blend);
          nd2.resize(blend);
          for (size_t j = 0; j < blend; ++j) {
            nd2[j] = top[j].first;
            near[j] = top[j].second;
          }
        } else {
          anchor_grid.nearest(pts[i], blend, near, nd2);
        }
        bool all_inside = true;
        for (uint32_t a : near) all_inside = all_inside && inside[a];
        if (!all_inside) {
          own_fit[i] = 1;
          if (!gathered) near_points.gather(grid, cs, fits.reach());
          gathered = true;
          out[i] = fits.fitAt(pts[i], b, &point_radius[i], near_points).project(pts[i]);
          continue;
        }
        // A distance-weighted blend of the nearest anchors' projections.
        const double h2 = std::max(1e-12, nd2.back() * 2.0);
        Vec3 sum = Vec3::Zero();
        double wsum = 0, rsum = 0;
        for (size_t j = 0; j < near.size(); ++j) {
          const double w = std::exp(-nd2[j] / h2);
          sum += w * surfaces[near[j]].project(pts[i]);
          rsum += w * anchor_radius[near[j]];
          wsum += w;
        }
        out[i] = sum / wsum;
        point_radius[i] = static_cast<float>(rsum / wsum);
      }
    }
  }
  size_t count = anchors.size();
  for (char f : own_fit) count += f;
  return count;
}

// How far each point moved from `pts` to result.cloud: per point, RMS and
// maximum, the good / fair / bad classes, and a warning when far more are bad
// than noise alone explains.
void classifyDisplacements(const std::vector<Vec3>& pts, const SmoothingParams& p, Smoothing& result) {
  const long n = static_cast<long>(pts.size());
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
}

}  // namespace

Smoothing smoothMls(const Cloud& cloud, const SmoothingParams& p, const Progress& progress) {
  checkSmoothingParams(cloud, p);
  const std::vector<Vec3>& pts = cloud.points;
  Smoothing result;
  result.cloud = cloud;
  result.displacement_m.resize(cloud.size());

  const Neighbourhood nb = chooseNeighbourhood(pts, p);
  result.measured_noise_m = nb.measured_noise_m;
  result.k_used = nb.k;
  {
    const LocalFits fits(pts, nb, p.polynomial_order);
    std::vector<float> point_radius(pts.size());
    if (p.anchor_ratio == 0 || p.polynomial_order == 1) {
      projectEveryPoint(fits, pts, result.cloud.points, point_radius);
      result.fitted_surfaces = pts.size();
    } else {
      result.fitted_surfaces =
          projectAnchored(fits, pts, p.anchor_ratio, nb.radius, progress, result.cloud.points, point_radius);
    }
    double radius_sum = 0;  // summed in index order: the same every run
    for (float r : point_radius) radius_sum += r;
    result.mean_radius_m = radius_sum / static_cast<double>(pts.size());
  }
  progress("smoothing", 1.0);
  classifyDisplacements(pts, p, result);
  return result;
}

}  // namespace sailshape
