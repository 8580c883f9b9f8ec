#include "analysis/design/sail_generator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {
namespace {

constexpr double kRad = kPi / 180.0;
constexpr int kCurveSamples = 4001;
constexpr int kRollSamples = 401;

// Monotone cubic (Fritsch–Carlson) through (x[i], y[i]); x strictly increasing.
double pchip(const std::vector<double>& x, const std::vector<double>& y, double t) {
  const size_t n = x.size();
  if (n == 1) return y[0];
  if (t <= x.front()) return y.front();
  if (t >= x.back()) return y.back();
  std::vector<double> h(n - 1), delta(n - 1), m(n);
  for (size_t i = 0; i + 1 < n; ++i) {
    h[i] = x[i + 1] - x[i];
    delta[i] = (y[i + 1] - y[i]) / h[i];
  }
  m[0] = delta[0];
  m[n - 1] = delta[n - 2];
  for (size_t i = 1; i + 1 < n; ++i) {
    if (delta[i - 1] * delta[i] <= 0) {
      m[i] = 0;
    } else {
      const double w1 = 2 * h[i] + h[i - 1], w2 = h[i] + 2 * h[i - 1];
      m[i] = (w1 + w2) / (w1 / delta[i - 1] + w2 / delta[i]);
    }
  }
  const size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), t) - x.begin()) - 1;
  const double s = (t - x[i]) / h[i], s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * y[i] + (s3 - 2 * s2 + s) * h[i] * m[i] + (-2 * s3 + 3 * s2) * y[i + 1] +
         (s3 - s2) * h[i] * m[i + 1];
}

// Mean line depth at chord fraction u: two cubic Hermite pieces meeting with
// zero slope at the draft, slopes a at the luff and −b at the leech.
double meanLine(const ProfileStation& st, double u) {
  const double c = st.camber_pct / 100.0, d = st.draft_pct / 100.0;
  const double a = st.entry_factor * c / d, b = st.exit_factor * c / (1.0 - d);
  if (u <= d) {
    const double s = u / d;
    return (s * s * s - 2 * s * s + s) * a * d + (-2 * s * s * s + 3 * s * s) * c;
  }
  const double s = (u - d) / (1.0 - d);
  return (2 * s * s * s - 3 * s * s + 1) * c - (s * s * s - s * s) * b * (1.0 - d);
}

std::vector<Vec3> arcUniform(const std::vector<Vec3>& line, int n) {
  std::vector<double> cum(line.size(), 0.0);
  for (size_t i = 1; i < line.size(); ++i) cum[i] = cum[i - 1] + (line[i] - line[i - 1]).norm();
  std::vector<Vec3> out(static_cast<size_t>(n));
  size_t j = 0;
  for (int i = 0; i < n; ++i) {
    const double s = cum.back() * i / (n - 1);
    while (j + 2 < cum.size() && cum[j + 1] < s) ++j;
    const double seg = cum[j + 1] - cum[j];
    const double t = seg > 0 ? std::clamp((s - cum[j]) / seg, 0.0, 1.0) : 0.0;
    out[static_cast<size_t>(i)] = line[j] + t * (line[j + 1] - line[j]);
  }
  return out;
}

Vec3 alongPolyline(const std::vector<Vec3>& uniform, double f) {
  const double x = std::clamp(f, 0.0, 1.0) * static_cast<double>(uniform.size() - 1);
  const size_t i = std::min(static_cast<size_t>(x), uniform.size() - 2);
  const double t = x - static_cast<double>(i);
  return uniform[i] + t * (uniform[i + 1] - uniform[i]);
}

void pushCylinder(std::vector<Vec3>& out, std::mt19937_64& rng, const Vec3& a, const Vec3& b, double radius,
                  double density) {
  const Vec3 axis = b - a;
  const double len = axis.norm();
  const Vec3 w = axis / len;
  const Vec3 u = w.unitOrthogonal(), v = w.cross(u);
  const size_t n = static_cast<size_t>(density * 2 * kPi * radius * len);
  std::uniform_real_distribution<double> U(0, 1);
  for (size_t i = 0; i < n; ++i) {
    const double phi = 2 * kPi * U(rng);
    out.push_back(a + U(rng) * axis + radius * (std::cos(phi) * u + std::sin(phi) * v));
  }
}

}  // namespace

std::string sailTypeName(SailType type) {
  switch (type) {
    case SailType::Main: return "main";
    case SailType::SquareTopMain: return "square-top";
    case SailType::Jib: return "jib";
    case SailType::Gennaker: return "gennaker";
  }
  return "main";
}

SailType parseSailType(const std::string& name) {
  if (name == "main" || name == "mainsail") return SailType::Main;
  if (name == "square-top" || name == "squaretop") return SailType::SquareTopMain;
  if (name == "jib" || name == "genoa") return SailType::Jib;
  if (name == "gennaker" || name == "spinnaker" || name == "asymmetric") return SailType::Gennaker;
  throw InvalidInput("[parseSailType] unknown sail type '" + name + "' (expected main, square-top, jib or gennaker)");
}

SailDesign exampleDesign(SailType type) {
  SailDesign d;
  d.type = type;
  switch (type) {
    case SailType::Main:
      break;
    case SailType::SquareTopMain:
      d.luff_m = 10.0;
      d.leech_m = 10.2;
      d.foot_m = 3.8;
      d.head_width_m = 1.2;
      d.stations = {{0.0, 8, 45, 6, 2, 2}, {0.5, 11, 44, 12, 2.2, 1.8}, {1.0, 9, 50, 24, 2, 2}};
      break;
    case SailType::Jib:
      d.luff_m = 10.5;
      d.leech_m = 9.6;
      d.foot_m = 3.4;
      d.tack = Vec3(3.4, 0.0, 0.6);
      d.rake_deg = 18.0;
      d.stations = {{0.0, 10, 40, 10, 2.2, 1.8}, {0.5, 12, 40, 15, 2.4, 1.6}, {1.0, 10, 42, 20, 2, 2}};
      break;
    case SailType::Gennaker:
      d.luff_m = 12.4;
      d.leech_m = 11.0;
      d.foot_m = 6.5;
      d.tack = Vec3(4.5, 0.0, 0.8);
      d.rake_deg = 24.0;
      d.luff_round_m = 0.35;
      d.luff_sag_m = 0.6;
      d.stations = {{0.0, 18, 45, 30, 2.4, 1.8}, {0.5, 24, 48, 40, 2.4, 1.8}, {1.0, 16, 50, 55, 2, 2}};
      break;
  }
  return d;
}

SailDesign scaleDesign(SailDesign d, double s) {
  if (!(s > 0) || !std::isfinite(s)) throw InvalidInput("[scaleDesign] scale must be > 0 (got " + std::to_string(s) + ")");
  d.luff_m *= s;
  d.leech_m *= s;
  d.foot_m *= s;
  d.head_width_m *= s;
  d.tack *= s;
  d.luff_round_m *= s;
  d.luff_sag_m *= s;
  d.leech_round_m *= s;
  return d;
}

void validateDesign(const SailDesign& d) {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v))
      throw InvalidInput(std::string("[validateDesign] ") + name + " must be > 0 (got " + std::to_string(v) + ")");
  };
  positive(d.luff_m, "luff_m");
  positive(d.leech_m, "leech_m");
  positive(d.foot_m, "foot_m");
  if (d.type == SailType::SquareTopMain) positive(d.head_width_m, "head_width_m");
  if (!(std::abs(d.lean_deg) < 60))
    throw InvalidInput("[validateDesign] lean_deg must be within ±60 (got " + std::to_string(d.lean_deg) + ")");
  if (d.stations.empty()) throw InvalidInput("[validateDesign] at least one profile station is needed");
  for (size_t i = 0; i < d.stations.size(); ++i) {
    const ProfileStation& s = d.stations[i];
    const std::string at = " at station " + std::to_string(i);
    if (!(s.fraction >= 0 && s.fraction <= 1) || (i > 0 && !(s.fraction > d.stations[i - 1].fraction)))
      throw InvalidInput("[validateDesign] station fractions must increase within [0, 1] (got " +
                         std::to_string(s.fraction) + at + ")");
    if (!(s.camber_pct >= 0 && s.camber_pct < 50))
      throw InvalidInput("[validateDesign] camber_pct must be in [0, 50) (got " + std::to_string(s.camber_pct) + at + ")");
    if (!(s.draft_pct > 5 && s.draft_pct < 95))
      throw InvalidInput("[validateDesign] draft_pct must be in (5, 95) (got " + std::to_string(s.draft_pct) + at + ")");
    if (!(s.entry_factor > 0 && s.entry_factor <= 3) || !(s.exit_factor > 0 && s.exit_factor <= 3))
      throw InvalidInput("[validateDesign] entry_factor and exit_factor must be in (0, 3]" + at);
    if (!(std::abs(s.twist_deg) < 90))
      throw InvalidInput("[validateDesign] twist_deg must be within ±90 (got " + std::to_string(s.twist_deg) + at + ")");
  }
}

SailSurface::SailSurface(const SailDesign& design) : design_(design) {
  validateDesign(design_);
  const SailDesign& d = design_;
  const double r = d.rake_deg * kRad;
  // Planform in the XZ plane before twist.
  const Vec3 up(-std::sin(r), 0, std::cos(r));     // along the luff
  const Vec3 aft(-std::cos(r), 0, -std::sin(r));   // perpendicular to the luff, aft
  const Vec3 T = d.tack, H = T + d.luff_m * up;
  const Vec3 top = d.type == SailType::SquareTopMain ? H + d.head_width_m * aft : H;
  // Clew: foot_m from the tack, leech_m from the top corner, aft of the luff.
  const Vec3 tt = top - T;
  const double dist = tt.norm();
  const double a = (d.foot_m * d.foot_m - d.leech_m * d.leech_m + dist * dist) / (2 * dist);
  const double h2 = d.foot_m * d.foot_m - a * a;
  if (h2 <= 0)
    throw InvalidInput("[SailSurface] luff " + std::to_string(d.luff_m) + ", leech " + std::to_string(d.leech_m) +
                       " and foot " + std::to_string(d.foot_m) + " m do not make a triangle");
  Vec3 perp = Vec3::UnitY().cross(tt / dist);  // in the XZ plane
  if (perp.dot(aft) < 0) perp = -perp;
  const Vec3 C = T + a * tt / dist + std::sqrt(h2) * perp;

  const double side = d.leeward_port ? 1.0 : -1.0;
  std::vector<Vec3> luff_flat(kCurveSamples), luff3(kCurveSamples), leech3(kCurveSamples);
  const Vec3 leech_dir = (top - C).normalized();
  Vec3 leech_out = Vec3::UnitY().cross(leech_dir);
  if (leech_out.dot(aft) < 0) leech_out = -leech_out;
  std::vector<double> station_f, station_twist;
  for (const auto& s : d.stations) {
    station_f.push_back(s.fraction);
    station_twist.push_back(s.twist_deg);
  }
  for (int i = 0; i < kCurveSamples; ++i) {
    const double t = static_cast<double>(i) / (kCurveSamples - 1);
    const double bump = 4 * t * (1 - t);
    luff_flat[i] = T + t * (H - T) - d.luff_round_m * bump * aft;
    luff3[i] = luff_flat[i] + side * d.luff_sag_m * bump * Vec3::UnitY();
    const Vec3 leech_flat = C + t * (top - C) + d.leech_round_m * bump * leech_out;
    // Twist: the planform chord swings about the vertical towards leeward.
    const double tw = pchip(station_f, station_twist, t) * kRad;
    const Eigen::AngleAxisd rot(-side * tw, Vec3::UnitZ());
    leech3[i] = luff3[i] + rot * (leech_flat - luff_flat[i]);
  }
  if (d.lean_deg != 0) {
    const Eigen::AngleAxisd lean(-side * d.lean_deg * kRad, Vec3::UnitX());
    for (int i = 0; i < kCurveSamples; ++i) {
      luff3[i] = T + lean * (luff3[i] - T);
      leech3[i] = T + lean * (leech3[i] - T);
    }
  }
  luff_ = arcUniform(luff3, kCurveSamples);
  leech_ = arcUniform(leech3, kCurveSamples);

  // Roll each section plane about its chord until it holds the surface normal at
  // the maximum-camber point; the normal there is ∂S/∂f × chord, since ∂S/∂u is
  // along the chord where the mean line is flat. A fixed point over all sections.
  plane_roll_rad_.assign(kRollSamples, 0.0);
  const double h = 1.0 / (kRollSamples - 1);
  for (int iteration = 0; iteration < 50; ++iteration) {
    double largest = 0;
    std::vector<double> next = plane_roll_rad_;
    for (int i = 0; i < kRollSamples; ++i) {
      const double f = i * h;
      const Vec3 c = leechPoint(f) - luffPoint(f);
      if (c.norm() < 1e-3) continue;
      const Vec3 c_hat = c.normalized();
      const double u = stationAt(f).draft_pct / 100.0;
      const double f0 = std::max(0.0, f - h), f1 = std::min(1.0, f + h);
      const Vec3 normal = (at(f1, u) - at(f0, u)).cross(c_hat);
      const Vec3 m = c_hat.cross(depthDirection(f));
      const Vec3 e = c_hat.cross(m);
      const double en = e.dot(normal);
      if (std::abs(en) < 1e-12) continue;
      const double delta = std::atan(-m.dot(normal) / en);
      next[i] += delta;
      largest = std::max(largest, std::abs(delta));
    }
    plane_roll_rad_ = next;
    if (largest < 1e-9) break;
  }
}

Vec3 SailSurface::depthDirection(double f) const {
  const Vec3 c = leechPoint(f) - luffPoint(f);
  const double side = design_.leeward_port ? 1.0 : -1.0;
  Vec3 n0 = c.cross(Vec3::UnitZ());
  if (n0.norm() < 1e-9 * std::max(1.0, c.norm())) n0 = c.unitOrthogonal();
  n0 = side * n0.normalized();
  if (plane_roll_rad_.empty() || c.norm() == 0) return n0;
  const double x = std::clamp(f, 0.0, 1.0) * (kRollSamples - 1);
  const size_t i = std::min(static_cast<size_t>(x), static_cast<size_t>(kRollSamples - 2));
  const double roll = plane_roll_rad_[i] + (x - static_cast<double>(i)) * (plane_roll_rad_[i + 1] - plane_roll_rad_[i]);
  const Vec3 m0 = c.normalized().cross(n0);
  return std::cos(roll) * n0 + std::sin(roll) * m0;
}

Vec3 SailSurface::luffPoint(double f) const { return alongPolyline(luff_, f); }
Vec3 SailSurface::leechPoint(double f) const { return alongPolyline(leech_, f); }

ProfileStation SailSurface::stationAt(double f) const {
  std::vector<double> x, camber, draft, twist, entry, exit;
  for (const auto& s : design_.stations) {
    x.push_back(s.fraction);
    camber.push_back(s.camber_pct);
    draft.push_back(s.draft_pct);
    twist.push_back(s.twist_deg);
    entry.push_back(s.entry_factor);
    exit.push_back(s.exit_factor);
  }
  ProfileStation st;
  st.fraction = f;
  st.camber_pct = pchip(x, camber, f);
  st.draft_pct = pchip(x, draft, f);
  st.twist_deg = pchip(x, twist, f);
  st.entry_factor = pchip(x, entry, f);
  st.exit_factor = pchip(x, exit, f);
  return st;
}

Vec3 SailSurface::at(double f, double u) const {
  const Vec3 L = luffPoint(f), R = leechPoint(f);
  const Vec3 c = R - L;
  const double len = c.norm();
  if (len < 1e-12) return L;
  return L + u * c + len * meanLine(stationAt(f), u) * depthDirection(f);
}

KnownSection SailSurface::section(double f) const {
  KnownSection k;
  const ProfileStation st = stationAt(f);
  k.fraction = f;
  k.luff_point = luffPoint(f);
  k.leech_point = leechPoint(f);
  k.chord_m = (k.leech_point - k.luff_point).norm();
  k.camber_pct = st.camber_pct;
  k.draft_pct = st.draft_pct;
  const Vec3 d = k.luff_point - k.leech_point;
  k.twist_deg = std::atan2(std::abs(d.y()), d.x()) / kRad;
  const double c = st.camber_pct / 100.0, dr = st.draft_pct / 100.0;
  k.entry_deg = std::atan(st.entry_factor * c / dr) / kRad;
  k.exit_deg = std::atan(st.exit_factor * c / (1 - dr)) / kRad;
  return k;
}

Mesh generateSailMesh(const SailDesign& design, int rows, int columns) {
  if (rows < 2 || columns < 2)
    throw InvalidInput("[generateSailMesh] rows and columns must be >= 2 (got " + std::to_string(rows) + ", " +
                       std::to_string(columns) + ")");
  const SailSurface surface(design);
  const bool pointed = design.type != SailType::SquareTopMain;
  Mesh mesh;
  auto index = [&](int i, int j) { return static_cast<uint32_t>(i * (columns + 1) + j); };
  const int full_rows = pointed ? rows : rows + 1;  // a pointed head is one vertex
  for (int i = 0; i < full_rows; ++i)
    for (int j = 0; j <= columns; ++j)
      mesh.vertices.push_back(surface.at(static_cast<double>(i) / rows, static_cast<double>(j) / columns));
  for (int i = 0; i + 1 < full_rows; ++i)
    for (int j = 0; j < columns; ++j) {
      mesh.triangles.push_back({index(i, j), index(i, j + 1), index(i + 1, j + 1)});
      mesh.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i + 1, j)});
    }
  if (pointed) {
    const uint32_t apex = static_cast<uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back(surface.head());
    for (int j = 0; j < columns; ++j) mesh.triangles.push_back({index(rows - 1, j), index(rows - 1, j + 1), apex});
  }
  return mesh;
}

Cloud sampleSail(const SailDesign& design, const ScanSimulation& sim) {
  if (sim.points == 0) throw InvalidInput("[sampleSail] points must be > 0");
  if (!(sim.noise_sigma_m >= 0)) throw InvalidInput("[sampleSail] noise_sigma_m must be >= 0");
  const SailSurface surface(design);
  // Area-weighted cells of a fine (f, u) grid, then uniform inside each cell.
  const int nf = 200, nu = 100;
  std::vector<double> cdf;
  cdf.reserve(static_cast<size_t>(nf * nu));
  double total = 0;
  for (int i = 0; i < nf; ++i)
    for (int j = 0; j < nu; ++j) {
      const double f0 = static_cast<double>(i) / nf, f1 = static_cast<double>(i + 1) / nf;
      const double u0 = static_cast<double>(j) / nu, u1 = static_cast<double>(j + 1) / nu;
      const Vec3 a = surface.at(f0, u0), b = surface.at(f0, u1), c = surface.at(f1, u0), e = surface.at(f1, u1);
      total += 0.5 * ((b - a).cross(c - a).norm() + (b - e).cross(c - e).norm());
      cdf.push_back(total);
    }
  std::mt19937_64 rng(sim.seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> N(0, 1);
  Cloud cloud;
  cloud.viewpoint = sim.viewpoint;
  cloud.points.reserve(sim.points);
  for (size_t k = 0; k < sim.points; ++k) {
    const size_t cell = static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), U(rng) * total) - cdf.begin());
    const int i = static_cast<int>(std::min(cell, cdf.size() - 1)) / nu, j = static_cast<int>(std::min(cell, cdf.size() - 1)) % nu;
    const double f = (i + U(rng)) / nf, u = (j + U(rng)) / nu;
    Vec3 p = surface.at(f, u);
    if (sim.noise_sigma_m > 0) p += sim.noise_sigma_m * N(rng) * (p - sim.viewpoint).normalized();
    cloud.points.push_back(p);
  }
  return cloud;
}

SceneCloud sampleSailScene(const SailDesign& design, const ScanSimulation& sim) {
  SceneCloud scene;
  scene.cloud = sampleSail(design, sim);
  scene.is_sail.assign(scene.cloud.size(), 1);
  const SailSurface surface(design);
  const double area = [&] {
    Mesh m = generateSailMesh(design, 60, 30);
    return meshArea(m);
  }();
  const double density = static_cast<double>(sim.points) / area;  // points per m²
  std::mt19937_64 rng(sim.seed + 7919);
  std::vector<Vec3> extra;
  const Vec3 tack = surface.tack(), head = surface.head(), clew = surface.clew();
  const double mast_r = 0.07;
  if (design.type == SailType::Main || design.type == SailType::SquareTopMain) {
    // Mast just forward of the luff (a luff groove gap of 2 cm), boom just below the foot.
    const Vec3 luff_dir = (head - tack).normalized();
    const Vec3 fwd = Vec3::UnitY().cross(luff_dir).normalized() * (Vec3::UnitY().cross(luff_dir).x() > 0 ? 1 : -1);
    const Vec3 mast_foot = tack + fwd * (mast_r + 0.02) - luff_dir * tack.z() / luff_dir.z();
    pushCylinder(extra, rng, mast_foot, head + fwd * (mast_r + 0.02) + luff_dir * 0.5, mast_r, density);
    const double boom_r = 0.06;
    const Vec3 below(0, 0, -(boom_r + 0.06));
    pushCylinder(extra, rng, tack + below, clew + below + (clew - tack).normalized() * 0.2, boom_r, density);
  } else {
    // Forestay-side hardware: a pulpit post at the tack.
    pushCylinder(extra, rng, Vec3(tack.x() + 0.3, 0.0, 0.0), Vec3(tack.x() + 0.3, 0.0, tack.z() - 0.1), 0.03,
                 density);
  }
  // Deck: a flat rectangle around the sail's foot at z = 0.
  const double x0 = std::min(tack.x(), clew.x()) - 1.0, x1 = std::max(tack.x(), clew.x()) + 1.0;
  std::uniform_real_distribution<double> U(0, 1);
  const size_t deck_n = static_cast<size_t>(density * 0.5 * (x1 - x0) * 2.4);  // sparser, as seen at grazing angles
  for (size_t i = 0; i < deck_n; ++i) extra.emplace_back(x0 + U(rng) * (x1 - x0), -1.2 + 2.4 * U(rng), 0.0);
  std::normal_distribution<double> N(0, 1);
  for (Vec3 p : extra) {
    if (sim.noise_sigma_m > 0) p += sim.noise_sigma_m * N(rng) * (p - sim.viewpoint).normalized();
    scene.cloud.points.push_back(p);
    scene.is_sail.push_back(0);
  }
  return scene;
}

}  // namespace sailshape
