#include "analysis/sections/sections.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/core/fit.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {
namespace {

// A stretch of a section curve bridged across a hole, chord coordinates (m).
struct Bridge {
  double x0 = 0, x1 = 0;
  double sd = 0;  // how far two fair curves across it disagree: the bridge's 1σ
};

struct Cut {
  std::vector<Vec3> points;
  std::vector<uint32_t> triangles;  // triangle of segment i → i+1
  std::vector<Bridge> bridges;      // stretches of `points` that bridge holes
};

struct Frame {
  Vec3 L, R, c_hat, y_hat, m;  // luff, leech, chord direction, in-plane normal to chord, plane normal
  double chord;
};

// Where the plane (point q, unit normal m) crosses the mesh edge a → b, whose
// signed distances from it are da and db (opposite signs). A flat facet is a
// chord of the curved sail: a straight edge L long sags κL²/8 below the surface
// (1-3 mm at the luff of a gennaker's upper sections, where its boundary
// triangles are 10-15 cm long and the section turns fast), and the entry and
// exit angles, read from the last tenth of the chord, follow such dips (by a degree
// or more on a clean gennaker's upper sections). The edge is taken as
// the cubic that leaves each end along the surface (the end's tangent plane,
// from its vertex normal: a PN-triangle edge), which lies on a circular arc to
// O(L⁴); the crossing is that cubic's, found by bisection between its ends.
// Where the two normals disagree by more than 60° (a fold, a stray vertex), or
// one is missing, the edge stays straight.
Vec3 crossEdge(const Mesh& mesh, const std::vector<Vec3>& normals, uint32_t a, uint32_t b, double da, double db,
               const Vec3& m) {
  const Vec3 &p0 = mesh.vertices[a], &p1 = mesh.vertices[b];
  const Vec3 e = p1 - p0;
  const double s = da / (da - db);
  const Vec3 &n0 = normals[a], &n1 = normals[b];
  if (n0.isZero() || n1.isZero() || std::abs(n0.dot(n1)) < 0.5) return p0 + s * e;
  const Vec3 b1 = p0 + (e - e.dot(n0) * n0) / 3.0, b2 = p1 - (e - e.dot(n1) * n1) / 3.0;
  auto at = [&](double u) {
    const double v = 1.0 - u;
    return Vec3(v * v * v * p0 + 3.0 * v * v * u * b1 + 3.0 * v * u * u * b2 + u * u * u * p1);
  };
  // Signed distance along the cubic, relative to the ends' (the same plane).
  double lo = 0, hi = 1;
  const bool rising = db > da;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double g = da + m.dot(at(mid) - p0);
    if ((g < 0) == rising) lo = mid;
    else hi = mid;
  }
  return at(0.5 * (lo + hi));
}

// Intersects the mesh (with its vertex normals) with the plane (point q, unit
// normal m) and returns the cut polylines, chained through shared mesh edges.
std::vector<Cut> cutMesh(const Mesh& mesh, const std::vector<Vec3>& normals, const Vec3& q, const Vec3& m) {
  std::vector<double> d(mesh.vertices.size());
  for (size_t i = 0; i < d.size(); ++i) {
    d[i] = m.dot(mesh.vertices[i] - q);
    if (d[i] == 0) d[i] = 1e-15;  // a vertex on the plane counts as above it
  }
  auto edgeKey = [](uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; };
  struct Link {
    uint64_t a = 0, b = 0;  // the two crossed edges of a cut triangle
    uint32_t tri = 0;
  };
  std::vector<Link> links;
  std::unordered_map<uint64_t, std::vector<uint32_t>> by_edge;  // edge → links using it
  std::unordered_map<uint64_t, Vec3> edge_point;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    uint64_t crossed[2];
    int c = 0;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = tri[e], b = tri[(e + 1) % 3];
      if ((d[a] > 0) == (d[b] > 0)) continue;
      const uint64_t k = edgeKey(a, b);
      if (!edge_point.count(k)) edge_point[k] = crossEdge(mesh, normals, a, b, d[a], d[b], m);
      if (c < 2) crossed[c++] = k;
    }
    if (c != 2) continue;
    by_edge[crossed[0]].push_back(static_cast<uint32_t>(links.size()));
    by_edge[crossed[1]].push_back(static_cast<uint32_t>(links.size()));
    links.push_back({crossed[0], crossed[1], t});
  }
  std::vector<char> used(links.size(), 0);
  std::vector<Cut> cuts;
  auto walk = [&](uint32_t start_link, uint64_t start_edge) {
    Cut cut;
    cut.points.push_back(edge_point[start_edge]);
    uint32_t link = start_link;
    uint64_t edge = start_edge;
    while (true) {
      used[link] = 1;
      const uint64_t other = links[link].a == edge ? links[link].b : links[link].a;
      cut.points.push_back(edge_point[other]);
      cut.triangles.push_back(links[link].tri);
      edge = other;
      uint32_t next = std::numeric_limits<uint32_t>::max();
      for (uint32_t l : by_edge[edge])
        if (!used[l]) next = l;
      if (next == std::numeric_limits<uint32_t>::max()) break;
      link = next;
    }
    cuts.push_back(std::move(cut));
  };
  // Open polylines first (they start at an edge with one link), then loops.
  for (uint32_t l = 0; l < links.size(); ++l) {
    if (used[l]) continue;
    if (by_edge[links[l].a].size() == 1) walk(l, links[l].a);
    else if (by_edge[links[l].b].size() == 1) walk(l, links[l].b);
  }
  for (uint32_t l = 0; l < links.size(); ++l)
    if (!used[l]) walk(l, links[l].a);
  return cuts;
}

// Least-squares polynomial of `degree` through the points xy (y over x), in
// u = (x - x0) / scale; coefficients by rising power.
Eigen::VectorXd polynomialThrough(const std::vector<Eigen::Vector2d>& xy, double x0, double scale, int degree) {
  std::vector<double> x(xy.size());
  Eigen::VectorXd y(static_cast<Eigen::Index>(xy.size()));
  for (size_t i = 0; i < xy.size(); ++i) {
    x[i] = xy[i].x();
    y[static_cast<Eigen::Index>(i)] = xy[i].y();
  }
  return fitPolynomial(x, y, degree, x0, scale).coeffs.col(0);
}

// Slope at x_end of a least-squares line (2 or 3 points) or quadratic (more)
// through the chord-coordinate points within `window` of x_end on one side.
double sideSlope(const std::vector<Eigen::Vector2d>& xy, double x_end, double window, bool left) {
  std::vector<Eigen::Vector2d> win;
  for (const auto& v : xy)
    if (left ? (v.x() <= x_end && v.x() >= x_end - window) : (v.x() >= x_end && v.x() <= x_end + window))
      win.push_back(v);
  if (win.size() < 2) return 0;
  return polynomialThrough(win, x_end, 1.0, win.size() >= 4 ? 2 : 1)[1];
}

// The curve across the gap between the chord-coordinate samples xy[i] and
// xy[i + 1] (sorted by x): the Hermite cubic that meets the curve on either side
// with its slope there. Its points inside the gap, evenly spaced about `step`
// apart, are appended to `inside`; its uncertainty (the returned bridge's sd) is
// its largest disagreement with one quadratic fitted to both sides.
Bridge bridgeGap(const std::vector<Eigen::Vector2d>& xy, size_t i, double chord, double step,
                 std::vector<Eigen::Vector2d>& inside) {
  const double xa = xy[i].x(), xb = xy[i + 1].x(), gap = xb - xa;
  const double ya = xy[i].y(), yb = xy[i + 1].y();
  const double window = std::max(0.05 * chord, 0.5 * gap);
  const double sa = sideSlope(xy, xa, window, true), sb = sideSlope(xy, xb, window, false);
  std::vector<Eigen::Vector2d> both;
  for (const auto& v : xy)
    if ((v.x() <= xa && v.x() >= xa - window) || (v.x() >= xb && v.x() <= xb + window)) both.push_back(v);
  const bool checked = both.size() >= 3;
  const Eigen::VectorXd q = checked ? polynomialThrough(both, xa, gap, 2) : Eigen::VectorXd::Zero(3);
  Bridge bridge{xa, xb, 0};
  const int n = std::max(2, static_cast<int>(std::ceil(gap / step)));
  for (int k = 1; k < n; ++k) {
    const double u = static_cast<double>(k) / n, u2 = u * u, u3 = u2 * u;
    const double y = (2 * u3 - 3 * u2 + 1) * ya + (u3 - 2 * u2 + u) * gap * sa + (-2 * u3 + 3 * u2) * yb +
                     (u3 - u2) * gap * sb;
    if (checked) bridge.sd = std::max(bridge.sd, std::abs(y - (q[0] + u * (q[1] + u * q[2]))));
    inside.emplace_back(xa + u * gap, y);
  }
  return bridge;
}

// The section curve from luff to leech: the cut pieces that lie over the chord
// (within half a chord of it, between its ends), joined in chord order. A cut
// is normally one piece; holes or non-manifold edges can break it into several.
// Gaps up to 10 % of the chord are kept as they are; wider ones inside the chord,
// up to max_bridged_gap, are bridged by the cubic that meets the curve on either
// side with its slope there. Returns false, saying why, when the curve does not
// span the chord: when it stops short of an end by more than 10 % of the chord
// and `end_allowance` (the band along the edges a scanner's beam footprint keeps
// it from, SailOutline::footprint_reach_m).
bool pickCut(std::vector<Cut>& cuts, const Frame& f, double max_bridged_gap, double end_allowance, Cut& out,
             std::string& why) {
  const Vec3& L = f.L;
  const double chord = f.chord;
  const Vec3& c_hat = f.c_hat;
  struct Sample {
    double x;
    Vec3 p;
    uint32_t tri;
  };
  std::vector<Sample> samples;
  for (const Cut& cut : cuts) {
    bool over_chord = false;
    for (const Vec3& p : cut.points) {
      const double x = (p - L).dot(c_hat);
      const double off = (p - L - x * c_hat).norm();
      if (x > -0.05 * chord && x < 1.05 * chord && off < 0.5 * chord) over_chord = true;
    }
    if (!over_chord) continue;
    for (size_t i = 0; i < cut.points.size(); ++i) {
      const Vec3& p = cut.points[i];
      const double x = (p - L).dot(c_hat);
      if (x < -0.05 * chord || x > 1.05 * chord || (p - L - x * c_hat).norm() > 0.5 * chord) continue;
      samples.push_back({x, p, cut.triangles[std::min(i, cut.triangles.size() - 1)]});
    }
  }
  if (samples.size() < 3) {
    why = "does not cut the sail between luff and leech";
    return false;
  }
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.x < b.x; });
  const double pct = 100.0 / chord;
  const double end_gap = 0.1 * chord + end_allowance;
  if (samples.front().x > end_gap || chord - samples.back().x > end_gap) {
    const bool luff = samples.front().x > end_gap;
    why = "leaves " + formatFixed(pct * (luff ? samples.front().x : chord - samples.back().x), 0) +
          " % of the chord at the " + (luff ? "luff" : "leech") + " uncovered (at most " +
          formatFixed(pct * end_gap, 0) + " %)";
    return false;
  }
  std::vector<Eigen::Vector2d> xy;
  std::vector<double> steps;
  for (size_t i = 0; i < samples.size(); ++i) {
    xy.emplace_back(samples[i].x, (samples[i].p - L).dot(f.y_hat));
    if (i > 0) steps.push_back(samples[i].x - samples[i - 1].x);
  }
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double step = std::max(steps[steps.size() / 2], 1e-3 * chord);
  out.points.clear();
  out.triangles.clear();
  out.bridges.clear();
  for (size_t i = 0; i < samples.size(); ++i) {
    out.points.push_back(samples[i].p);
    out.triangles.push_back(samples[i].tri);
    if (i + 1 == samples.size()) break;
    const double xa = samples[i].x, xb = samples[i + 1].x, gap = xb - xa;
    if (gap <= 0.1 * chord) continue;
    if (gap > max_bridged_gap * chord) {
      why = "crosses a hole " + formatFixed(pct * gap, 0) + " % of the chord wide (bridged up to " +
            formatFixed(100 * max_bridged_gap, 0) + " %)";
      return false;
    }
    std::vector<Eigen::Vector2d> inside;
    const Bridge bridge = bridgeGap(xy, i, chord, step, inside);
    for (const Eigen::Vector2d& v : inside) {
      out.points.push_back(L + v.x() * c_hat + v.y() * f.y_hat);
      out.triangles.push_back(samples[i].tri);
    }
    out.bridges.push_back(bridge);
  }
  return true;
}

struct QuadFit {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();  // y = c0 + c1 u + c2 u², u = x - x0
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  bool ok = false;
};

// Least-squares quadratic with the coefficients' covariance; `floor_sigma`
// bounds the residual σ from below (a perfect fit still has sensor noise).
// `anchored` fixes c0 = 0: the curve passes through (x0, 0), as a section
// passes through its own luff and leech points.
QuadFit fitQuadratic(const std::vector<Eigen::Vector2d>& xy, double x0, double floor_sigma, bool anchored = false) {
  QuadFit f;
  const int first = anchored ? 1 : 0, cols = 3 - first;
  if (xy.size() < static_cast<size_t>(cols + 1)) return f;
  Eigen::MatrixXd A(xy.size(), cols);
  Eigen::VectorXd y(xy.size());
  for (size_t i = 0; i < xy.size(); ++i) {
    const double u = xy[i].x() - x0;
    const double basis[3] = {1, u, u * u};
    for (int k = 0; k < cols; ++k) A(static_cast<Eigen::Index>(i), k) = basis[first + k];
    y[static_cast<Eigen::Index>(i)] = xy[i].y();
  }
  const Eigen::MatrixXd AtA = A.transpose() * A;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(AtA);
  if (!lu.isInvertible()) return f;
  const Eigen::VectorXd c = lu.solve(A.transpose() * y);
  const double rss = (A * c - y).squaredNorm();
  const double s2 = std::max(rss / static_cast<double>(xy.size() - static_cast<size_t>(cols)), floor_sigma * floor_sigma);
  const Eigen::MatrixXd cov = s2 * lu.inverse();
  f.c.tail(cols) = c;
  f.cov.bottomRightCorner(cols, cols) = cov;
  f.ok = true;
  return f;
}

// Maximum of a cubic fitted around the deepest cut point: a cubic follows the
// asymmetric crest of a real section (fuller forward than aft), so a wide
// window can average the noise without biasing the draft. Returns false when
// the fit has no maximum inside the window.
struct Peak {
  double x = 0, depth = 0, sd_x = 0, sd_depth = 0;
};
bool fitPeak(const std::vector<Eigen::Vector2d>& xy, double x0, double half_window, double floor_sigma, Peak& peak) {
  if (xy.size() < 8) return false;
  Eigen::MatrixXd A(xy.size(), 4);
  Eigen::VectorXd y(xy.size());
  for (size_t i = 0; i < xy.size(); ++i) {
    const double u = (xy[i].x() - x0) / half_window;
    A.row(static_cast<Eigen::Index>(i)) << 1, u, u * u, u * u * u;
    y[static_cast<Eigen::Index>(i)] = xy[i].y();
  }
  const Eigen::Matrix4d AtA = A.transpose() * A;
  Eigen::FullPivLU<Eigen::Matrix4d> lu(AtA);
  if (!lu.isInvertible()) return false;
  const Eigen::Vector4d c = lu.solve(A.transpose() * y);
  const double s2 = std::max((A * c - y).squaredNorm() / static_cast<double>(xy.size() - 4), floor_sigma * floor_sigma);
  const Eigen::Matrix4d cov = s2 * lu.inverse();
  // Stationary point with negative curvature nearest to the window's centre (u in [-1, 1]).
  auto crest = [](const Eigen::Vector4d& k, double& u_out) {
    const double a = 3 * k[3], b = 2 * k[2], cc = k[1];
    double roots[2];
    int n = 0;
    if (std::abs(a) < 1e-12) {
      if (std::abs(b) > 1e-12) roots[n++] = -cc / b;
    } else {
      const double disc = b * b - 4 * a * cc;
      if (disc >= 0) {
        roots[n++] = (-b + std::sqrt(disc)) / (2 * a);
        roots[n++] = (-b - std::sqrt(disc)) / (2 * a);
      }
    }
    bool found = false;
    for (int i = 0; i < n; ++i) {
      const double u = roots[i];
      if (std::abs(u) > 1 || 2 * k[2] + 6 * k[3] * u >= 0) continue;
      if (!found || std::abs(u) < std::abs(u_out)) u_out = u;
      found = true;
    }
    return found;
  };
  auto value = [](const Eigen::Vector4d& k, double u) { return k[0] + u * (k[1] + u * (k[2] + u * k[3])); };
  double u = 0;
  if (!crest(c, u)) return false;
  peak.x = x0 + u * half_window;
  peak.depth = value(c, u);
  // Uncertainty: numerical gradient of (x, depth) with respect to the coefficients.
  Eigen::Vector4d gx, gd;
  for (int k = 0; k < 4; ++k) {
    const double h = 1e-6 * std::max(1e-3, std::abs(c[k]));
    Eigen::Vector4d cp = c;
    cp[k] += h;
    double up = u;
    if (!crest(cp, up)) up = u;
    gx[k] = (up - u) * half_window / h;
    gd[k] = (value(cp, up) - peak.depth) / h;
  }
  peak.sd_x = std::sqrt(std::max(0.0, gx.dot(cov * gx)));
  peak.sd_depth = std::sqrt(std::max(0.0, gd.dot(cov * gd)));
  return true;
}

// Covariance inflation for n points over `span` metres whose noise is
// correlated over `correlation` metres: n / n_effective.
double correlationInflation(size_t n, double span, double correlation) {
  if (correlation <= 0 || n == 0) return 1.0;
  const double n_eff = std::max(3.0, span / correlation);
  return std::max(1.0, static_cast<double>(n) / n_eff);
}

std::vector<Eigen::Vector2d> toChordCoords(const Cut& cut, const Frame& f) {
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(cut.points.size());
  for (const Vec3& p : cut.points) xy.emplace_back((p - f.L).dot(f.c_hat), (p - f.L).dot(f.y_hat));
  return xy;
}

size_t maxDepthIndex(const std::vector<Eigen::Vector2d>& xy, double chord) {
  size_t best = 0;
  double best_y = -1;
  for (size_t i = 0; i < xy.size(); ++i)
    if (xy[i].x() >= 0 && xy[i].x() <= chord && std::abs(xy[i].y()) > best_y) {
      best_y = std::abs(xy[i].y());
      best = i;
    }
  return best;
}

// Area-weighted mean normal of the triangles within `radius` of p.
Vec3 surfaceNormalNear(const Mesh& mesh, const Vec3& p, double radius, uint32_t fallback_tri) {
  Vec3 sum = Vec3::Zero();
  const double r2 = radius * radius;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3 centre = (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3.0;
    if ((centre - p).squaredNorm() > r2) continue;
    sum += (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
  }
  if (sum.norm() == 0) return triangleNormal(mesh, fallback_tri);
  return sum.normalized();
}

std::vector<Vec3> resampleCurve(const std::vector<Vec3>& line, int n) {
  std::vector<Vec3> out;
  if (n < 2 || line.size() < 2) return line;
  out.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) out.push_back(pointAtFraction(line, static_cast<double>(i) / (n - 1)));
  return out;
}

}  // namespace

std::vector<std::vector<Vec3>> planeCuts(const Mesh& mesh, const Vec3& point, const Vec3& normal) {
  if (!(normal.norm() > 0) || !normal.allFinite())
    throw InvalidInput("[planeCuts] the plane's normal must be finite and non-zero");
  std::vector<std::vector<Vec3>> out;
  for (Cut& c : cutMesh(mesh, vertexNormals(mesh), point, normal.normalized())) out.push_back(std::move(c.points));
  return out;
}

double twistDeg(const Vec3& luff_point, const Vec3& leech_point) {
  const Vec3 d = luff_point - leech_point;
  return std::atan2(std::abs(d.y()), d.x()) * kDegPerRad;
}

std::vector<double> sectionFractions(const SectionParams& p) {
  std::vector<double> f = p.fractions;
  if (f.empty()) {
    if (p.count < 1 || p.count > 100)
      throw InvalidInput("[cutSections] count must be in [1, 100] (got " + std::to_string(p.count) + ")");
    for (int k = 1; k <= p.count; ++k) f.push_back(static_cast<double>(k) / (p.count + 1));
  }
  for (double t : f)
    if (!(t > 0 && t < 1))
      throw InvalidInput("[cutSections] section fractions must be in (0, 1) (got " + std::to_string(t) + ")");
  std::sort(f.begin(), f.end());
  return f;
}

void checkSectionParams(const SectionParams& p) {
  if (p.plane != "normal" && p.plane != "perpendicular" && p.plane != "horizontal")
    throw InvalidInput("[cutSections] plane must be normal, perpendicular or horizontal (got '" + p.plane + "')");
  if (!(p.end_window > 0 && p.end_window <= 0.5))
    throw InvalidInput("[cutSections] end_window must be in (0, 0.5] (got " + std::to_string(p.end_window) + ")");
  if (!(p.max_bridged_gap >= 0 && p.max_bridged_gap < 1))
    throw InvalidInput("[cutSections] max_bridged_gap must be in [0, 1) (got " + std::to_string(p.max_bridged_gap) + ")");
  if (!(p.peak_window > 0 && p.peak_window <= 0.5))
    throw InvalidInput("[cutSections] peak_window must be in (0, 0.5] (got " + std::to_string(p.peak_window) + ")");
  auto need = [](bool ok, const std::string& what, double got) {
    if (!ok) throw InvalidInput("[cutSections] " + what + " (got " + formatFixed(got, 6) + ")");
  };
  need(p.normal_tolerance_deg > 0, "normal_tolerance_deg must be > 0", p.normal_tolerance_deg);
  need(p.max_tilt_deg > 0 && p.max_tilt_deg < 90, "max_tilt_deg must be in (0, 90)", p.max_tilt_deg);
  need(p.max_iterations >= 0, "max_iterations must be >= 0", p.max_iterations);
  need(p.normal_radius > 0 && p.normal_radius <= 0.5, "normal_radius must be in (0, 0.5]", p.normal_radius);
  need(p.sensor_sigma_m >= 0, "sensor_sigma_m must be >= 0 (0: an exact surface)", p.sensor_sigma_m);
  need(p.noise_correlation_m >= 0, "noise_correlation_m must be >= 0", p.noise_correlation_m);
  need(p.surface_sigma_m >= 0, "surface_sigma_m must be >= 0", p.surface_sigma_m);
  need(p.curve_points >= 2, "curve_points must be >= 2", p.curve_points);
  sectionFractions(p);
}

namespace {

// What every section of one sail shares: its outline, the corners' plane, the
// chord ends' uncertainties and the mesh's vertex normals.
struct SectionGeometry {
  const SailOutline& outline;
  Vec3 corner_normal;
  double spacing, sigma_luff, sigma_ends;  // sigma_ends: of the chord vector, per axis
  std::vector<Vec3> normals;
};

// The chord of the section at fraction t: its luff and leech points, length and
// direction (f.y_hat and f.m are left for the plane). Throws AnalysisError when
// there is none.
Frame sectionChord(double t, const SailOutline& outline, const SectionParams& p) {
  Frame f;
  f.L = pointAtFraction(outline.luff, t);
  if (p.plane == "horizontal") {
    // The leech point is where the leech crosses the luff point's height.
    bool found = false;
    for (size_t i = 1; i < outline.leech.size() && !found; ++i) {
      const Vec3 &a = outline.leech[i - 1], &b = outline.leech[i];
      if ((a.z() - f.L.z()) * (b.z() - f.L.z()) <= 0 && a.z() != b.z()) {
        f.R = a + (f.L.z() - a.z()) / (b.z() - a.z()) * (b - a);
        found = true;
      }
    }
    if (!found)
      throw AnalysisError("[cutSections] horizontal plane at z = " + std::to_string(f.L.z()) +
                          " m does not cross the leech");
  } else {
    f.R = pointAtFraction(outline.leech, t);
  }
  f.chord = (f.R - f.L).norm();
  if (f.chord <= 0) throw AnalysisError("[cutSections] zero chord at fraction " + formatFixed(t, 3));
  f.c_hat = (f.R - f.L) / f.chord;
  return f;
}

// A section plane through the chord, tilted about it by phi (rad) from the
// starting plane, with the curve it cuts from the sail.
struct SectionPlane {
  Frame f;
  Cut cut;
  double phi = 0;
  bool converged = false;  // the plane stands along the surface normal at the crest (or needs not)
};

// The section plane at fraction t through the chord `chord` (from sectionChord):
// the starting plane (square to the corners' plane, or horizontal), and with
// plane "normal" the tilt about the chord that brings it along the surface normal
// at the crest. Warnings about it go to `warnings`; throws AnalysisError when the
// starting plane finds no curve spanning the chord.
SectionPlane findSectionPlane(double t, const Mesh& mesh, const SectionParams& p, const SectionGeometry& g,
                              const Frame& chord, std::vector<std::string>& warnings) {
  const Frame& f0 = chord;
  Vec3 m0 = p.plane == "horizontal" ? Vec3::UnitZ() : f0.c_hat.cross(g.corner_normal);
  if (m0.norm() < 1e-9) m0 = f0.c_hat.cross(Vec3::UnitZ());
  m0.normalize();
  const Vec3 e0 = f0.c_hat.cross(m0);

  SectionPlane plane;
  plane.f = f0;
  Frame& f = plane.f;
  double& phi = plane.phi;
  Cut& cut = plane.cut;
  // The cut at rotation `angle` about the chord; false (and f, cut as they were)
  // when that plane finds no curve spanning the chord.
  std::string why;
  auto cutAt = [&](double angle) {
    Frame tilted = f;
    tilted.m = (std::cos(angle) * m0 + std::sin(angle) * e0).normalized();
    tilted.y_hat = tilted.m.cross(tilted.c_hat);
    auto cuts = cutMesh(mesh, g.normals, tilted.L, tilted.m);
    Cut c;
    if (!pickCut(cuts, tilted, p.max_bridged_gap, g.outline.footprint_reach_m, c, why)) return false;
    f = tilted;
    cut = std::move(c);
    phi = angle;
    return true;
  };
  if (!cutAt(0)) throw AnalysisError("[cutSections] the section plane at fraction " + formatFixed(t, 3) + " " + why);
  plane.converged = true;
  if (p.plane != "normal") return plane;
  plane.converged = false;
  // A tilted plane that loses the curve (it leaves the sail through a hole or an
  // uncovered end) ends the search at the last plane that held it.
  auto tiltTo = [&](double angle) {
    if (cutAt(angle)) return true;
    warnings.push_back("section " + formatFixed(t, 3) + ": the plane tilted " +
                       formatFixed(angle * kDegPerRad, 1) + " deg " + why + "; kept at " +
                       formatFixed(phi * kDegPerRad, 1) + " deg");
    return false;
  };
  for (int it = 0; it < p.max_iterations; ++it) {
    const auto xy = toChordCoords(cut, f);
    const size_t imax = maxDepthIndex(xy, f.chord);
    const uint32_t tri = cut.triangles[std::min(imax, cut.triangles.size() - 1)];
    const Vec3 n = surfaceNormalNear(mesh, cut.points[imax], p.normal_radius * f.chord, tri);
    const Vec3 e = f.c_hat.cross(f.m);
    const double out_of_plane = std::asin(std::clamp(f.m.dot(n), -1.0, 1.0)) * kDegPerRad;
    if (std::abs(out_of_plane) <= p.normal_tolerance_deg) {
      plane.converged = true;
      break;
    }
    const double en = e.dot(n);
    if (std::abs(en) < 1e-9) break;
    const double next = phi + std::atan(-f.m.dot(n) / en);
    if (std::abs(next) * kDegPerRad > p.max_tilt_deg) {
      tiltTo(std::copysign(p.max_tilt_deg / kDegPerRad, next));
      break;
    }
    if (!tiltTo(next)) break;
  }
  if (!plane.converged)
    warnings.push_back("section " + formatFixed(t, 3) + ": the plane did not reach the surface normal within " +
                       std::to_string(p.normal_tolerance_deg) + " deg");
  return plane;
}

// Whether chord coordinate x lies inside one of the bridges (m).
bool inBridge(const std::vector<Bridge>& bridges, double x) {
  for (const Bridge& b : bridges)
    if (x > b.x0 && x < b.x1) return true;
  return false;
}

// The section's maximum depth (m, from the chord) and where along the chord it
// stands (m from the luff point), with their 1σ; side: which side of the chord
// (±1 along f.y_hat) the crest lies on.
struct Crest {
  double side = 1, depth = 0, depth_x = 0, sd_depth = 0, sd_x = 0;
};

// The crest of the curve xy (chord coordinates, m): the deepest point, refined by
// a cubic through the points around it. `spacing`: the outline's sample spacing (m),
// the crest's place's σ when no cubic fits.
Crest measureCrest(double t, const std::vector<Eigen::Vector2d>& xy, const Frame& f, const Cut& cut,
                   const SectionParams& p, double spacing, std::vector<std::string>& warnings) {
  const size_t imax = maxDepthIndex(xy, f.chord);
  Crest c;
  c.side = xy[imax].y() >= 0 ? 1.0 : -1.0;
  const double side = c.side;
  double depth = std::abs(xy[imax].y()), depth_x = xy[imax].x();
  double sd_depth = p.sensor_sigma_m, sd_x = spacing;
  {
    std::vector<Eigen::Vector2d> win;
    for (const auto& v : xy)
      if (std::abs(v.x() - depth_x) <= p.peak_window * f.chord) win.emplace_back(v.x(), side * v.y());
    Peak peak;
    const double half_window = p.peak_window * f.chord, peak_x0 = depth_x;
    if (fitPeak(win, peak_x0, half_window, p.surface_sigma_m, peak)) {
      const double inflate =
          std::sqrt(correlationInflation(win.size(), 2 * half_window, p.noise_correlation_m));
      depth = peak.depth;
      depth_x = peak.x;
      sd_depth = peak.sd_depth * inflate;
      sd_x = peak.sd_x * inflate;
      // A crest the cubic does not follow (a mean line whose curvature changes
      // there, fuller on one side than a cubic allows) moves the fitted maximum by
      // about as much as the window is wide. The same fit over the window's middle
      // half lies half as far off: twice their difference, less what their noise
      // alone makes of it (for nested least-squares fits, the difference of their
      // variances), estimates the full window's bias, which the draft's σ carries.
      // The draft itself stays the full window's: 2·x_middle − x_full, free of
      // that bias, errs instead where a cubic does follow the crest (a cubic mean line).
      std::vector<Eigen::Vector2d> middle;
      for (const auto& v : win)
        if (std::abs(v.x() - peak_x0) <= 0.5 * half_window) middle.push_back(v);
      Peak inner;
      if (fitPeak(middle, peak_x0, 0.5 * half_window, p.surface_sigma_m, inner)) {
        const double var_full = sd_x * sd_x;
        const double var_middle =
            std::pow(inner.sd_x, 2) * correlationInflation(middle.size(), half_window, p.noise_correlation_m);
        const double shift = inner.x - peak.x;
        sd_x = std::sqrt(var_full + 4.0 * std::max(0.0, shift * shift - std::max(0.0, var_middle - var_full)));
      }
      // A bridge under the crest's window carries its own uncertainty into the
      // depth; a crest inside it could stand anywhere across it.
      for (const Bridge& b : cut.bridges) {
        if (b.x1 < depth_x - p.peak_window * f.chord || b.x0 > depth_x + p.peak_window * f.chord) continue;
        sd_depth = std::hypot(sd_depth, b.sd);
        if (depth_x > b.x0 && depth_x < b.x1) sd_x = std::hypot(sd_x, (b.x1 - b.x0) / std::sqrt(12.0));
      }
    } else {
      warnings.push_back("section " + formatFixed(t, 3) +
                         ": no crest in the peak fit; the deepest cut point is used");
    }
  }
  c.depth = depth;
  c.depth_x = depth_x;
  c.sd_depth = sd_depth;
  c.sd_x = sd_x;
  return c;
}

// Entry (at_luff) or exit angle (deg): a quadratic over the first / last end_window
// of chord, its slope at the end; its 1σ (deg, NaN with the angle when too few
// points) goes to sd_deg. xy: the curve in chord coordinates (m), side: the
// crest's (Crest::side).
// A sparse section (a small sail, the upper sections of a coarse scan) may hold only
// a few cut points there; the window then widens until it holds kWantedEndPoints, to
// at most twice end_window (a quadratic over 20 % of a sail's mean line leaves its end
// slope within about half a degree), with a warning. The cut points lie on the mesh's
// flat facets, whose slopes step by about a degree from facet to facet on a curved
// section 4 cm apart: ten points average those steps to a quarter of a degree.
double endAngle(bool at_luff, double t, const std::vector<Eigen::Vector2d>& xy, const Frame& f, double side,
                const Cut& cut, const SectionParams& p, std::vector<std::string>& warnings, double& sd_deg,
                std::map<std::string, std::string>& not_measured) {
  constexpr size_t kMinEndPoints = 6, kWantedEndPoints = 10;
  const char* const which = at_luff ? "entry" : "exit";
  std::vector<Eigen::Vector2d> win;
  const double x_end = at_luff ? 0.0 : f.chord;
  const double widest = std::min(0.5, 2.0 * p.end_window);
  double window = p.end_window;
  for (;;) {
    win.clear();
    for (const auto& v : xy)  // measured points only: a bridge is no evidence of the end's slope
      if (std::abs(v.x() - x_end) <= window * f.chord && !inBridge(cut.bridges, v.x()))
        win.emplace_back(v.x(), side * v.y());
    if (win.size() >= kWantedEndPoints || window >= widest) break;
    window = std::min(widest, 1.25 * window);
  }
  // Fewer even then: five points leave a quadratic two degrees of freedom, and its
  // end slope can err by ten degrees on a clean sail.
  const QuadFit q = win.size() >= kMinEndPoints ? fitQuadratic(win, x_end, p.surface_sigma_m) : QuadFit{};
  if (!q.ok) {
    sd_deg = std::numeric_limits<double>::quiet_NaN();
    const std::string why = "too few points for the " + std::string(which) + " angle (" + std::to_string(win.size()) +
                            " within " + formatFixed(100 * window, 0) + " % of the chord)";
    warnings.push_back("section " + formatFixed(t, 3) + ": " + why);
    not_measured[std::string(which) + "_deg"] = why;
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (window > p.end_window)
    warnings.push_back("section " + formatFixed(t, 3) + ": the " + which + " angle is read from " +
                       std::to_string(win.size()) + " points over " + formatFixed(100 * window, 0) +
                       " % of the chord (too few within " + formatFixed(100 * p.end_window, 0) + " %)");
  const double slope = at_luff ? q.c[1] : -q.c[1];
  const double span = window * f.chord;
  double inflate = correlationInflation(win.size(), span, p.noise_correlation_m);
  // A window shorter than the noise's correlation length sees the surface's error
  // as one smooth tilt, whose slope spreads by the error over that length, not
  // over the window: σ/span would grow without bound on short chords.
  if (span < p.noise_correlation_m) inflate *= (span / p.noise_correlation_m) * (span / p.noise_correlation_m);
  sd_deg = std::sqrt(q.cov(1, 1) * inflate) / (1 + slope * slope) * kDegPerRad;
  return std::atan(slope) * kDegPerRad;
}

// How the corners' places (each known to its σ along its bisector) move the chord
// of the section at fraction t: they move its ends along the luff and the leech,
// the sections standing at arc fractions from the foot (SPEC §5): the luff point by
// (1 − t) of the tack's shift and t of the head's, the leech point likewise from
// the clew and the head (or the peak). A shared head moves both ends alike, and its
// share of a change in the chord (luff point − leech point) cancels as far as the
// edges run alike.
class CornerSpread {
 public:
  CornerSpread(const SailOutline& outline, double t) {
    const double top_sigma = outline.has_peak ? outline.peak_sigma_m : 0.0;
    shifts_[0] = {outline.tack_sigma_m, 1.0 - t, 0.0};
    shifts_[1] = {outline.clew_sigma_m, 0.0, 1.0 - t};
    shifts_[2] = {outline.head_sigma_m, t, outline.has_peak ? 0.0 : t};
    shifts_[3] = {top_sigma, 0.0, t};
    auto tangentAt = [&](const std::vector<Vec3>& line) {
      constexpr double kStep = 1e-3;  // of the edge's arc
      const Vec3 d =
          pointAtFraction(line, std::min(1.0, t + kStep)) - pointAtFraction(line, std::max(0.0, t - kStep));
      return d.norm() > 0 ? Vec3(d.normalized()) : Vec3::Zero();
    };
    luff_tangent_ = tangentAt(outline.luff);
    leech_tangent_ = tangentAt(outline.leech);
  }
  // 1σ (m) of the chord vector's component along unit d.
  double sd(const Vec3& d) const {
    double var = 0;
    for (const CornerShift& c : shifts_)
      var += std::pow(c.sigma_m * d.dot(c.luff_share * luff_tangent_ - c.leech_share * leech_tangent_), 2);
    return std::sqrt(var);
  }

 private:
  struct CornerShift {
    double sigma_m, luff_share, leech_share;
  };
  CornerShift shifts_[4];
  Vec3 luff_tangent_, leech_tangent_;
};

// One section at fraction t, per SPEC §5; warnings about it go to `warnings`.
// Throws AnalysisError when it cannot be measured (cutSections lists it unmeasured).
Section measureSection(double t, const Mesh& mesh, const SectionParams& p, const SectionGeometry& g,
                       std::vector<std::string>& warnings) {
  const double sigma_luff = g.sigma_luff, sigma_ends = g.sigma_ends;
  Section s;
  s.fraction = t;
  const SectionPlane plane = findSectionPlane(t, mesh, p, g, sectionChord(t, g.outline, p), warnings);
  const Frame& f = plane.f;
  const Cut& cut = plane.cut;
  s.converged = plane.converged;
  s.plane_tilt_deg = plane.phi * kDegPerRad;
  s.plane_normal = f.m;
  s.luff_point = f.L;
  s.leech_point = f.R;
  // A chord's end where the samples stop short of the sail's edge (grazing, range, a
  // shadow, samples left out of the surface) is where the scan stopped, not the luff or leech: the chord, and every
  // value along it, would be short by however much of the sail was not seen.
  for (const auto& [end, name] : {std::pair<const Vec3*, const char*>{&f.L, "luff"}, {&f.R, "leech"}})
    if (auto why = g.outline.coverage.shortOfEdgeNear(g.outline.boundary, *end))
      throw AnalysisError("[cutSections] its " + std::string(name) + " end is not the sail's edge: " + *why);
  const auto xy = toChordCoords(cut, f);
  s.curve_samples = xy.size();
  for (const Bridge& b : cut.bridges) s.bridged_pct += 100.0 * (b.x1 - b.x0) / f.chord;
  if (!cut.bridges.empty())
    warnings.push_back("section " + formatFixed(t, 3) + ": a hole in the scan, " +
                              formatFixed(s.bridged_pct, 0) + " % of the chord, is bridged");

  const Crest crest = measureCrest(t, xy, f, cut, p, g.spacing, warnings);
  s.max_camber_point = f.L + crest.depth_x * f.c_hat + crest.side * crest.depth * f.y_hat;

  SectionParameters& v = s.value;
  SectionParameters& u = s.uncertainty;
  v.chord_m = f.chord;
  v.camber_pct = 100.0 * crest.depth / f.chord;
  v.draft_pct = 100.0 * crest.depth_x / f.chord;
  v.twist_deg = twistDeg(f.L, f.R);
  v.entry_deg = endAngle(true, t, xy, f, crest.side, cut, p, warnings, u.entry_deg, s.not_measured);
  v.exit_deg = endAngle(false, t, xy, f, crest.side, cut, p, warnings, u.exit_deg, s.not_measured);
  const double chord_dir_sd = sigma_ends / f.chord;  // rad
  const double chord_xy = std::hypot(f.R.x() - f.L.x(), f.R.y() - f.L.y());
  // The corners' places move the chord's ends along the edges (CornerSpread);
  // across the edges, sigma_ends alone.
  const CornerSpread corners(g.outline, t);
  u.chord_m = std::hypot(sigma_ends, corners.sd(f.c_hat));
  // The chord line moves by about half the ends' uncertainty at the crest.
  u.camber_pct = 100.0 * std::sqrt(crest.sd_depth * crest.sd_depth + 0.25 * sigma_ends * sigma_ends) / f.chord;
  u.draft_pct = 100.0 * std::sqrt(crest.sd_x * crest.sd_x + sigma_luff * sigma_luff) / f.chord;
  if (chord_xy > 0) {
    const Vec3 across_xy(-(f.R.y() - f.L.y()) / chord_xy, (f.R.x() - f.L.x()) / chord_xy, 0.0);
    u.twist_deg = std::hypot(sigma_ends, corners.sd(across_xy)) / chord_xy * kDegPerRad;
  } else {
    u.twist_deg = 180.0;
  }
  u.entry_deg = std::hypot(u.entry_deg, chord_dir_sd * kDegPerRad);
  u.exit_deg = std::hypot(u.exit_deg, chord_dir_sd * kDegPerRad);

  std::vector<Vec3> line = cut.points;
  s.curve = resampleCurve(line, p.curve_points);
  return s;
}

}  // namespace

SectionAnalysis cutSections(const Mesh& mesh, const SailOutline& outline, const SectionParams& p) {
  checkSectionParams(p);
  if (mesh.empty()) throw InvalidInput("[cutSections] empty mesh");
  if (outline.luff.size() < 2 || outline.leech.size() < 2)
    throw InvalidInput("[cutSections] outline has no luff or leech");
  const std::vector<double> fractions = sectionFractions(p);
  // A section sits at a fraction of the luff and the leech from the tack and the clew
  // up to the head (or peak): with a corner the scan never reached, those lengths, and
  // where the fractions fall, are unknown.
  if (!outline.coverage.allCornersReached()) {
    std::string why;
    for (const std::string& u : outline.coverage.unreached) why += (why.empty() ? "" : "; ") + u;
    throw AnalysisError("[cutSections] no section can be placed, the scan did not reach every corner: " + why);
  }

  // Plane of the corners: its normal starts every section plane.
  const Vec3 top = outline.has_peak ? 0.5 * (outline.head + outline.peak) : outline.head;
  Vec3 corner_normal = (outline.clew - outline.tack).cross(top - outline.tack);
  if (corner_normal.norm() == 0) throw AnalysisError("[cutSections] the corners are collinear");
  corner_normal.normalize();
  const double spacing = outline.boundary_spacing_m;
  // Chord end uncertainties: the fitted edges' own, or sampling and sensor noise
  // when the outline does not carry them.
  const double sigma_fallback = std::sqrt(p.sensor_sigma_m * p.sensor_sigma_m + spacing * spacing / 12.0);
  const double sigma_luff = outline.luff_sigma_m > 0 ? outline.luff_sigma_m : sigma_fallback;
  const double sigma_leech = outline.leech_sigma_m > 0 ? outline.leech_sigma_m : sigma_fallback;
  const SectionGeometry geometry{outline, corner_normal, spacing, sigma_luff, std::hypot(sigma_luff, sigma_leech),
                                 vertexNormals(mesh)};
  SectionAnalysis result;
  for (double t : fractions) {
    // A section whose plane finds no curve across the chord is left unmeasured;
    // the others stand.
    try {
      result.sections.push_back(measureSection(t, mesh, p, geometry, result.warnings));
    } catch (const AnalysisError& e) {
      std::string why = e.what();
      const std::string prefix = "[cutSections] ";
      if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
      result.unmeasured.push_back({t, why});
      result.warnings.push_back("section " + formatFixed(t, 3) + " not measured: " + why);
    }
  }
  if (result.sections.empty()) {
    std::string why;
    for (const UnmeasuredSection& u : result.unmeasured) why += (why.empty() ? "" : "; ") + u.reason;
    throw AnalysisError("[cutSections] " + (result.unmeasured.size() == 1 ? why : "no section could be measured: " + why));
  }
  if (!result.unmeasured.empty() && result.unmeasured.front().fraction < result.sections.front().fraction)
    result.warnings.push_back("twist_rel is relative to the lowest measured section, at fraction " +
                              formatFixed(result.sections.front().fraction, 3));
  setTwistRelative(result.sections);
  return result;
}

void setTwistRelative(std::vector<Section>& sections) {
  if (sections.empty()) return;
  const Section& low = sections.front();
  for (Section& s : sections) {
    s.value.twist_rel_deg = s.value.twist_deg - low.value.twist_deg;
    s.uncertainty.twist_rel_deg = &s == &low ? 0.0 : std::hypot(s.uncertainty.twist_deg, low.uncertainty.twist_deg);
  }
}

}  // namespace sailshape
