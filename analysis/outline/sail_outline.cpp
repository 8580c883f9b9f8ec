#include "analysis/outline/sail_outline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>

#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"
#include "analysis/spatial/neighbours.hpp"
#include "analysis/segmentation/plane_detection.hpp"

#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace sailshape {
namespace {

// The simple loops a closed walk is made of: the walk cut at each vertex it
// returns to. A vertex may be passed more than once; each pass closes the loop
// since the last.
std::vector<std::vector<uint32_t>> simpleLoops(const std::vector<uint32_t>& walk) {
  std::vector<std::vector<uint32_t>> loops;
  std::vector<uint32_t> stack;
  std::unordered_map<uint32_t, size_t> at;  // vertex → its position on the stack
  for (uint32_t v : walk) {
    const auto it = at.find(v);
    if (it != at.end()) {
      const size_t from = it->second;
      loops.emplace_back(stack.begin() + static_cast<long>(from), stack.end());
      for (size_t i = from + 1; i < stack.size(); ++i) at.erase(stack[i]);
      stack.resize(from + 1);
      continue;
    }
    at[v] = stack.size();
    stack.push_back(v);
  }
  loops.push_back(std::move(stack));
  return loops;
}

// The longest closed loop of boundary edges: directed edges a→b used by exactly
// one triangle whose reverse b→a no triangle uses. Edges are bucketed by their
// lower vertex (counting sort, linear in the mesh) instead of hashed: the mesh
// of a 200,000-point scan has 1.2 million directed edges.
std::vector<uint32_t> outerBoundaryLoop(const Mesh& mesh) {
  const size_t nv = mesh.vertices.size();
  // Each undirected edge under its lower vertex: the other vertex and whether the
  // triangle runs lower→higher.
  struct Half {
    uint32_t other;
    bool up;
  };
  std::vector<uint32_t> start(nv + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      if (std::max(a, b) >= nv)
        throw InvalidInput("[extractOutline] a triangle uses vertex " + std::to_string(std::max(a, b)) +
                           " of a mesh with " + std::to_string(nv) + " vertices");
      if (a != b) ++start[std::min(a, b) + 1];  // a self-edge is its own reverse: never a boundary
    }
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<Half> halves(start[nv]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& t : mesh.triangles)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = t[e], b = t[(e + 1) % 3];
        if (a == b) continue;
        halves[fill[std::min(a, b)]++] = {std::max(a, b), a < b};
      }
  }
  // Boundary edges (from, to), in the order of their lower vertex.
  std::vector<std::pair<uint32_t, uint32_t>> boundary;
  for (uint32_t v = 0; v < nv; ++v) {
    const Half* h = halves.data() + start[v];
    const size_t m = start[v + 1] - start[v];
    for (size_t i = 0; i < m; ++i) {
      bool seen = false;  // this vertex pair already counted at an earlier slot
      for (size_t j = 0; j < i && !seen; ++j) seen = h[j].other == h[i].other;
      if (seen) continue;
      int up = 0, down = 0;
      for (size_t j = i; j < m; ++j)
        if (h[j].other == h[i].other) ++(h[j].up ? up : down);
      if (up == 1 && down == 0) boundary.emplace_back(v, h[i].other);
      if (down == 1 && up == 0) boundary.emplace_back(h[i].other, v);
    }
  }
  if (boundary.empty()) throw AnalysisError("[extractOutline] the mesh has no boundary edge (closed surface?)");
  // Outgoing boundary edges of each vertex: out_to[out_start[v] .. out_start[v + 1]).
  std::vector<uint32_t> out_start(nv + 1, 0), out_to(boundary.size());
  for (const auto& [a, b] : boundary) ++out_start[a + 1];
  for (size_t v = 0; v < nv; ++v) out_start[v + 1] += out_start[v];
  {
    std::vector<uint32_t> fill(out_start.begin(), out_start.end() - 1);
    for (const auto& [a, b] : boundary) out_to[fill[a]++] = b;
  }
  std::vector<char> used(boundary.size(), 0);
  std::vector<uint32_t> best, loop;
  double best_len = -1;
  for (uint32_t from = 0; from < nv; ++from)
    for (uint32_t first_edge = out_start[from]; first_edge < out_start[from + 1]; ++first_edge) {
      if (used[first_edge]) continue;
      loop.assign(1, from);
      uint32_t edge = first_edge;
      bool closed = false;
      while (true) {
        used[edge] = 1;
        const uint32_t nxt = out_to[edge];
        if (nxt == from) {
          closed = true;
          break;
        }
        loop.push_back(nxt);
        bool found = false;
        for (uint32_t e = out_start[nxt]; e < out_start[nxt + 1] && !found; ++e)
          if (!used[e]) {
            edge = e;
            found = true;
          }
        if (!found || loop.size() > boundary.size()) break;
      }
      if (!closed || loop.size() < 3) continue;
      // A hole that touches the outline at one vertex (where two triangles meet
      // only at their tips) joins the walk there: the walk goes round the hole
      // and back out. Each simple loop of the walk is a candidate on its own; a
      // hole's excursion kept in the outline is a deep notch whose turn reads as
      // a corner (a gennaker's clew was found in mid-luff).
      for (const std::vector<uint32_t>& simple : simpleLoops(loop)) {
        if (simple.size() < 3) continue;
        double len = 0;
        for (size_t i = 0; i < simple.size(); ++i)
          len += (mesh.vertices[simple[i]] - mesh.vertices[simple[(i + 1) % simple.size()]]).norm();
        if (len > best_len) {
          best_len = len;
          best = simple;
        }
      }
    }
  if (best.empty()) throw AnalysisError("[extractOutline] the mesh boundary does not form a closed loop");
  return best;
}

// Point on a closed loop at arc position s (wrapped), given cumulative arc lengths.
Vec3 loopPointAt(const std::vector<Vec3>& pts, const std::vector<double>& cum, double total, double s) {
  s = std::fmod(s, total);
  if (s < 0) s += total;
  const size_t i = static_cast<size_t>(std::upper_bound(cum.begin(), cum.end(), s) - cum.begin()) - 1;
  const size_t j = (i + 1) % pts.size();
  const double seg = (i + 1 < cum.size() ? cum[i + 1] : total) - cum[i];
  const double t = seg > 0 ? (s - cum[i]) / seg : 0.0;
  return pts[i] + t * (pts[j] - pts[i]);
}

// Least-squares polynomials of one variable s, one per column of values:
// Σ_k c_k u^k with u = (s − mid) / half, the samples' range mapped onto [−1, 1].
struct Polynomial {
  Eigen::MatrixXd coeffs;  // (degree + 1) × columns
  double mid = 0, half = 1;

  Eigen::RowVectorXd at(double s) const {
    const double u = (s - mid) / half;
    Eigen::RowVectorXd v = Eigen::RowVectorXd::Zero(coeffs.cols());
    double uk = 1;
    for (Eigen::Index k = 0; k < coeffs.rows(); ++k, uk *= u) v += uk * coeffs.row(k);
    return v;
  }
};

// `values` has one row per entry of s.
Polynomial fitPolynomial(const std::vector<double>& s, const Eigen::MatrixXd& values, int degree) {
  Polynomial p;
  const double lo = *std::min_element(s.begin(), s.end()), hi = *std::max_element(s.begin(), s.end());
  p.mid = 0.5 * (lo + hi);
  p.half = std::max(1e-9, 0.5 * (hi - lo));
  Eigen::MatrixXd A(static_cast<Eigen::Index>(s.size()), degree + 1);
  for (size_t i = 0; i < s.size(); ++i) {
    const double u = (s[i] - p.mid) / p.half;
    double uk = 1;
    for (int k = 0; k <= degree; ++k, uk *= u) A(static_cast<Eigen::Index>(i), k) = uk;
  }
  p.coeffs = A.colPivHouseholderQr().solve(values);
  return p;
}

// A smooth edge: a point for each s, in metres of boundary arc from the edge's
// first corner.
struct EdgeCurve : Polynomial {
  Vec3 at(double s) const { return Polynomial::at(s).transpose(); }
  Vec3 tangent(double s) const {
    const double h = 1e-4 * half;
    return (at(s + h) - at(s - h)).normalized();
  }
};

EdgeCurve fitEdgeCurve(const std::vector<Vec3>& pts, const std::vector<double>& s, int degree) {
  Eigen::MatrixXd xyz(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) xyz.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
  return EdgeCurve{fitPolynomial(s, xyz, degree)};
}

// One sail edge as found on the boundary: its points from corner to corner
// with their arc positions, moved out to the true edge, and the fitted curve.
struct Edge {
  std::vector<Vec3> points;   // boundary points moved out by `recess`
  std::vector<double> s;      // arc position of each point from the first corner, metres
  double length = 0;
  double exclude = 0;         // arc near each corner left out of the curve fit (corners are rounded off)
  EdgeCurve curve;            // fitted on [exclude, length − exclude]
  double recess = 0;          // how far the sampled boundary lies inside the true edge
  // The spacing of scan lines running beside the edge, when its samples lie on such
  // lines (GapShape; 0: a scatter): the edge lies up to one beyond the last line.
  double line_spacing = 0;
  bool along_lines = false;  // its curve runs along its samples' lower envelope (lowerEnvelope)
  bool on_envelope = false;  // a scatter's edge whose curve moved onto its samples' lower envelope
  double sigma = 0;           // 1σ position uncertainty of the fitted curve, as the corners' crossing takes it
  // 1σ of the curve between the corners, where the sections end on it: `sigma`, or,
  // where the curve runs on its samples' lower envelope, the envelope's own (its band
  // and its mean offset from the windows' curve). The envelope is measured from the
  // windows' curve, so that curve's scatter cancels out of it: on clean 40,000-point
  // gennakers `sigma` said 2.4-3.6 mm where the luff and leech lie 1.0-1.4 mm RMS off.
  double section_sigma = 0;
  double scatter = 0;         // RMS distance of the points from the fitted curve, m
};

// The recess δ from the outermost samples: the samples' offsets o from the found
// edge (positive inwards, o <= D) in windows `window` long along it; in a window
// of n, uniform on [−δ, D], the least lies above −δ by a gap near exponential
// with mean (D + δ)/(n + 1). The median over the windows (a stray sample beyond
// the edge spoils only its own window) exceeds the mean of such gaps' estimates
// by (1 − ln 2) of a mean gap; that is taken off.
// A window of n samples whose offsets are uniform on [−δ, D]: the least lies a
// gap above −δ, E[gap] = (D + δ)/(n + 1), so −least = δ − gap + E[gap], solved for δ.
double recessFromLeast(double least, double D, double n) {
  const double q = 1.0 / (n + 1.0);
  return (q * D - least) / (1.0 - q);
}

// The edge's strip and windows, in boundary spacings: samples within 4 inside
// the found edge, in windows 5 long along it (fitEdge's always; ontoFrontier's
// 1/8 of a shorter edge's reach, but no less than a spacing: frontierWindow).
constexpr double kFrontierStripSpacings = 4.0, kFrontierWindowSpacings = 5.0;
constexpr double kFrontierFewestWindows = 8.0;
// ontoFrontier's windows take their strip's depth in this many parts along them.
constexpr size_t kFrontierDepthParts = 8;
// How well the beam footprint's reach across an edge is known, as a fraction of it:
// beam figures vary by unit (SPEC §3), and whether an edge return leaves the sail
// depends on what lies behind it.
constexpr double kFootprintUncertainty = 0.25;

// Calls f(a, b) for each run [a, b) of `sorted` (samples (arc position, offset) in
// ascending arc position) that starts where the last one ended and reaches less than
// `window` along from its first sample; each holds one sample at least.
template <typename F>
void forEachWindow(const std::vector<std::pair<double, double>>& sorted, double window, F&& f) {
  for (size_t a = 0; a < sorted.size();) {
    size_t b = a + 1;
    while (b < sorted.size() && sorted[b].first < sorted[a].first + window) ++b;
    f(a, b);
    a = b;
  }
}

struct Frontier {
  double recess = 0;                  // m
  size_t windows = 0;
  std::vector<double> centre, local;  // each window's mid arc position and recess estimate, m
  double median = 0;                  // of `local`, m
  double mean_gap = 0;                // m
};

// `along_offset` as forEachWindow takes it: ascending in arc position.
Frontier frontierRecess(const std::vector<std::pair<double, double>>& along_offset, double D, double window) {
  Frontier f;
  if (!(window > 0)) return f;  // no spacing to step by
  struct Window {
    double centre, span, least;
    size_t n;
  };
  std::vector<Window> windows;
  forEachWindow(along_offset, window, [&](size_t a, size_t b) {
    double least = std::numeric_limits<double>::infinity();
    for (size_t j = a; j < b; ++j) least = std::min(least, along_offset[j].second);
    if (b - a >= 8)
      windows.push_back({0.5 * (along_offset[a].first + along_offset[b - 1].first),
                         along_offset[b - 1].first - along_offset[a].first, least, b - a});
  });
  if (windows.empty()) return f;
  // Samples per full window: the median count (near a narrow corner the strip
  // reaches across the sail and holds fewer, though the outermost lies as close).
  std::vector<size_t> counts;
  for (const Window& w : windows) counts.push_back(w.n);
  std::nth_element(counts.begin(), counts.begin() + static_cast<long>(counts.size() / 2), counts.end());
  const double n_full = static_cast<double>(counts[counts.size() / 2]);
  std::vector<double> deltas;
  double gap_sum = 0;
  for (const Window& w : windows) {
    const double n = std::max(1.0, n_full * std::min(1.0, w.span / window));
    deltas.push_back(recessFromLeast(w.least, D, n));
    gap_sum += (D + std::max(deltas.back(), 0.0)) / (n + 1.0);
    f.centre.push_back(w.centre);
    f.local.push_back(deltas.back());
  }
  f.windows = deltas.size();
  if (deltas.empty()) return f;
  const double n = static_cast<double>(deltas.size());
  const double mean_gap = gap_sum / n;
  f.mean_gap = mean_gap;
  std::nth_element(deltas.begin(), deltas.begin() + static_cast<long>(deltas.size() / 2), deltas.end());
  f.median = deltas[deltas.size() / 2];
  f.recess = f.median - (1.0 - std::log(2.0)) * mean_gap;
  return f;
}

// The samples of a surface near its boundary: the mesh's vertices, their
// normals and a grid over them.
struct Samples {
  const Mesh& mesh;
  const std::vector<Vec3>& normals;
  const PointGrid& tree;
};

// Across an edge through `at` with unit tangent t: the direction into the
// surface, the mean normal of the 24 vertices nearest `near` × t, turned towards
// their centroid (unit to within how far t leaves the surface); and `at` moved
// along that normal onto the vertices' plane.
struct Across {
  Vec3 in = Vec3::Zero();
  Vec3 on_surface = Vec3::Zero();
};
Across acrossAt(const Vec3& near, const Vec3& at, const Vec3& t, const Samples& smp, std::vector<uint32_t>& idx,
                std::vector<double>& d2) {
  smp.tree.nearest(near, 24, idx, d2);
  Vec3 n = Vec3::Zero(), centre = Vec3::Zero();
  for (uint32_t v : idx) {
    n += smp.normals[v];
    centre += smp.mesh.vertices[v];
  }
  centre /= static_cast<double>(idx.size());
  n.normalize();
  Across a;
  a.in = n.cross(t);
  if (a.in.dot(centre - at) < 0) a.in = -a.in;
  a.on_surface = at - (at - centre).dot(n) * n;
  return a;
}

// How the samples beside an edge lie across it. Sorted by offset within a window,
// consecutive samples leave gaps G; the expected distance from an edge placed at
// random among them to the first sample is E[G²] / (2 E[G]) (the residual life of
// a stationary point process). A uniform scatter leaves exponential gaps, and that
// distance equals the mean gap: the ratio read 0.99-1.07 on every edge of 40,000-point
// mains and gennakers. Scan lines running beside the edge (a 2D scanner on a
// turntable, its cloud given without the scan angles) put many samples at one
// offset and leave a line spacing s between lines: the residual distance is s / 2,
// many mean gaps (2-9 on luffs with lines 4-6 cm apart, bench/independent-sails).
struct GapShape {
  double mean_gap = 0;  // m
  double residual = 0;  // E[G²] / (2 E[G]), m
  double gaps = 0;      // how many gaps they were read from
  double ratio() const { return mean_gap > 0 ? residual / mean_gap : 0; }
};

// `along_offset` ascending in arc position, as for frontierRecess.
GapShape gapShape(const std::vector<std::pair<double, double>>& along_offset, double window) {
  GapShape g;
  if (!(window > 0)) return g;
  double sum = 0, sum2 = 0, gaps = 0;
  std::vector<double> o;
  forEachWindow(along_offset, window, [&](size_t a, size_t b) {
    if (b - a < 8) return;
    o.clear();
    for (size_t j = a; j < b; ++j) o.push_back(along_offset[j].second);
    std::sort(o.begin(), o.end());
    for (size_t j = 1; j < o.size(); ++j) {
      const double gap = o[j] - o[j - 1];
      sum += gap;
      sum2 += gap * gap;
      gaps += 1;
    }
  });
  if (gaps > 0 && sum > 0) {
    g.mean_gap = sum / gaps;
    g.residual = sum2 / (2.0 * sum);
    g.gaps = gaps;
  }
  return g;
}

// Samples beside an edge lie on scan lines when the ratio passes 1.5 by more than
// its spread over a scatter, which falls as 1/√gaps and is wide: one wide gap moves
// it. Over 90 uniform runs (bench/independent-sails: main, square top, gennaker;
// 5,000-40,000 points; clean, noisy, scenes, holes) it reached 2.66 from 307 gaps
// and 1.71 from 3,424; luffs on scan lines read 2.1 (3,172 gaps) to 9.3 (5,069).
bool onScanLines(const GapShape& g) { return g.gaps > 0 && g.ratio() > 1.5 + 30.0 / std::sqrt(g.gaps); }

// The lower envelope of samples (s, o) (o positive inwards): the polynomial of the
// given degree that lies beyond (o below) the outermost sample of every stretch
// `window` long and is as far in as that allows on the whole (a linear programme:
// maximise Σ p(s_w) subject to p(s_w) ≤ least_w, solved exactly by CGAL). Where scan
// lines cross an edge, each line ends on it, so the envelope touches the line ends
// and is the edge; a fit through the outermost samples would follow the staircase
// the last line leaves between crossings. nullopt when the programme has no optimum.
// `along_offset` ascending in arc position, as for frontierRecess.
std::optional<Polynomial> lowerEnvelope(const std::vector<std::pair<double, double>>& along_offset, double window, int degree) {
  std::vector<double> s, least;
  forEachWindow(along_offset, window, [&](size_t a, size_t b) {
    size_t at = a;
    for (size_t j = a + 1; j < b; ++j)
      if (along_offset[j].second < along_offset[at].second) at = j;
    s.push_back(along_offset[at].first);
    least.push_back(along_offset[at].second);
  });
  degree = std::min(degree, static_cast<int>(s.size() / 4) - 1);
  if (degree < 1) return std::nullopt;
  Polynomial p;
  p.mid = 0.5 * (s.front() + s.back());
  p.half = std::max(1e-9, 0.5 * (s.back() - s.front()));
  CGAL::Quadratic_program<double> lp(CGAL::SMALLER, false, 0, false, 0);
  std::vector<double> objective(static_cast<size_t>(degree) + 1, 0.0);
  for (size_t w = 0; w < s.size(); ++w) {
    const double u = (s[w] - p.mid) / p.half;
    double uk = 1;
    for (int k = 0; k <= degree; ++k, uk *= u) {
      lp.set_a(k, static_cast<int>(w), uk);
      objective[static_cast<size_t>(k)] -= uk;
    }
    lp.set_b(static_cast<int>(w), least[w]);
  }
  for (int k = 0; k <= degree; ++k) lp.set_c(k, objective[static_cast<size_t>(k)]);
  const CGAL::Quadratic_program_solution<CGAL::Gmpzf> solution = CGAL::solve_linear_program(lp, CGAL::Gmpzf());
  if (!solution.is_optimal()) return std::nullopt;
  p.coeffs = Eigen::MatrixXd::Zero(degree + 1, 1);
  int k = 0;
  for (auto it = solution.variable_values_begin(); it != solution.variable_values_end(); ++it, ++k)
    p.coeffs(k, 0) = CGAL::to_double(*it);
  return p;
}

// A sampled surface's boundary lies inside the true edge: the outermost samples
// sit some distance in. Sample offsets from the true edge are uniform on
// [0, ∞), so within the strip o ≤ D of the found edge (offset o from it,
// positive inwards) they are uniform on [−δ, D]. The recess δ comes from the
// outermost samples of each stretch of the edge (frontierRecess), or, on an edge
// too short for that, from δ = D − 2·mean(o); the edge's points are moved out by
// it and the curve is fitted again.
void fitEdge(Edge& e, const Samples& smp, double spacing) {
  const Mesh& mesh = smp.mesh;
  const PointGrid& tree = smp.tree;
  e.length = e.s.back();
  e.exclude = std::max(0.03 * e.length, 6.0 * spacing);
  std::vector<size_t> inner;
  for (size_t i = 0; i < e.points.size(); ++i)
    if (e.s[i] >= e.exclude && e.s[i] <= e.length - e.exclude) inner.push_back(i);
  if (inner.size() < 6) {  // a very short edge: keep every point
    inner.clear();
    for (size_t i = 0; i < e.points.size(); ++i) inner.push_back(i);
    e.exclude = 0;
  }

  const int degree = static_cast<int>(std::clamp<size_t>(inner.size() / 8, 1, 5));
  auto fit = [&] {
    std::vector<Vec3> pts;
    std::vector<double> s;
    for (size_t i : inner) {
      pts.push_back(e.points[i]);
      s.push_back(e.s[i]);
    }
    e.curve = fitEdgeCurve(pts, s, degree);
  };
  fit();

  // Inward direction at each point: surface normal × tangent, towards the mesh.
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  std::vector<Vec3> inward(e.points.size());
  for (size_t i = 0; i < e.points.size(); ++i) {
    const double si = std::clamp(e.s[i], e.exclude, e.length - e.exclude);
    inward[i] = acrossAt(e.points[i], e.curve.at(si), e.curve.tangent(si), smp, idx, d2).in;
  }

  const double strip = kFrontierStripSpacings * spacing;
  // The samples in the strip beside the edge, as (arc position, offset o) with
  // lowest <= o <= strip: round the points `at` of the edge, each within a spacing
  // along it of `centre(i)` (tangent `tangent(i)`), offsets along inward[i]. The
  // disc searched must hold the whole window |along| <= spacing, 0 <= o <= strip: a
  // disc of radius `strip` alone cuts its far corners, thins the samples near
  // o = strip and so overstates the recess (by about 0.08 × spacing).
  auto stripSamples = [&](const std::vector<size_t>& at, auto centre, auto tangent, double lowest) {
    std::vector<std::pair<double, double>> out;
    std::vector<char> seen(mesh.vertices.size(), 0);
    for (size_t i : at) {
      const Vec3 c = centre(i), t = tangent(i);
      tree.withinRadius(c, std::hypot(strip, spacing), idx, d2);
      for (uint32_t v : idx) {
        if (seen[v]) continue;
        const Vec3 d = mesh.vertices[v] - c;
        if (std::abs(d.dot(t)) > spacing) continue;  // belongs to a neighbouring point
        seen[v] = 1;
        const double o = d.dot(inward[i]);
        if (o <= strip && o >= lowest) out.emplace_back(e.s[i] + d.dot(t), o);
      }
    }
    return out;
  };
  std::vector<size_t> every_other;
  for (size_t k = 0; k < inner.size(); k += 2) every_other.push_back(inner[k]);
  std::vector<std::pair<double, double>> along_offset = stripSamples(
      every_other, [&](size_t i) { return e.curve.at(e.s[i]); }, [&](size_t i) { return e.curve.tangent(e.s[i]); },
      -std::numeric_limits<double>::infinity());
  double sum = 0;
  for (const auto& [along, o] : along_offset) sum += o;
  const size_t count = along_offset.size();
  // δ's σ: offsets spread over about the strip width, uniform.
  double sigma_recess = strip / std::sqrt(3.0);
  bool on_envelope = false;  // the curve moved onto the samples' lower envelope
  if (count >= 30) {
    e.recess = std::clamp(strip - 2.0 * sum / static_cast<double>(count), 0.0, strip);
    sigma_recess = 2.0 * strip / std::sqrt(12.0 * static_cast<double>(count));
  }
  // The mean of the offsets uses every sample in the strip but spreads with the
  // strip's width: 2 mm on a 10 m luff at 40,000 points, which tilts an upper
  // section's chord by 0.15°. The outermost sample of each stretch of the edge
  // lies inside it by a gap that spreads only as much as it is long (about a
  // millimetre there): estimates from those are several times sharper. They
  // also hold after smoothing, which pulls a noisy scan's outermost samples in
  // less than the samples behind them (the mean came out 3-6 mm short there).
  std::sort(along_offset.begin(), along_offset.end());  // for the windows along the edge
  const Frontier frontier = count >= 30 ? frontierRecess(along_offset, strip, kFrontierWindowSpacings * spacing) : Frontier{};
  // The frontier model below is a scatter's; on scan lines it places the edge by the
  // last line, up to a line spacing inside (extractOutline says so and widens σ).
  if (count >= 30) {
    const GapShape gaps = gapShape(along_offset, kFrontierWindowSpacings * spacing);
    if (onScanLines(gaps)) e.line_spacing = 2.0 * gaps.residual;
  }
  if (frontier.windows >= 6) {
    e.recess = std::clamp(frontier.recess, 0.0, strip);
    // The recess along the edge: a polynomial of the curve's degree (at most a
    // third as many coefficients as windows) through the windows' estimates, each
    // held within 4 mean gaps of their median (a stray beyond the edge). It takes
    // out the curve's own wiggles, which a least-squares fit through boundary
    // samples scattered by one gap each leaves at 3-5 mm on a gennaker's luff.
    const size_t m = frontier.local.size();
    const int deg = std::min(degree, static_cast<int>(m / 3) - 1);
    Eigen::VectorXd held(static_cast<Eigen::Index>(m));
    for (size_t j = 0; j < m; ++j)
      held[static_cast<Eigen::Index>(j)] = std::clamp(frontier.local[j], frontier.median - 4.0 * frontier.mean_gap,
                                                      frontier.median + 4.0 * frontier.mean_gap);
    const Polynomial recess = fitPolynomial(frontier.centre, held, deg);
    const double first = frontier.centre.front(), last = frontier.centre.back();
    for (size_t i = 0; i < e.points.size(); ++i) {
      const double d = recess.at(std::clamp(e.s[i], first, last))[0];  // held at the end windows' value beyond them
      e.points[i] -= std::clamp(d, 0.0, strip) * inward[i];
    }
    sigma_recess = frontier.mean_gap * std::sqrt(static_cast<double>(deg + 1) / static_cast<double>(m));
    fit();
    // The windows' estimates spread as their gaps do: (D + δ)/(n + 1) each, a
    // few millimetres, which a fit through them averages down only as the root of
    // their count (1.4 mm across a 40,000-point gennaker's luff, 0.06° of twist at
    // its 3/4 section). All the samples beside the edge at once place it sharper:
    // the polynomial lying beyond every one of them and as far in as that allows
    // (their lower envelope, as on scan lines) misses the true edge by the band
    // that holds, on average, as many samples as it has coefficients, q + 1 over
    // the strip's density ρ and the edge's length L: (q + 1)/(ρ L) inside it, with
    // about as much spread. (Over uniform scatters in simulation, mean and spread
    // 0.92-1.02 and 0.8-1.0 times that, for degrees 0-5 and edges 3-12.5 m long.)
    // It is moved out by that. On a 40,000-point gennaker that is 0.7 mm on the luff.
    // The envelope rests on the outermost samples and nothing else, so noise across
    // the edge (range noise in a scan that meets the sail obliquely) pulls it out by
    // the noise's extremes, where the windows' estimates move by its mean: it is
    // kept only while it lies, over most of the edge (its median offset), within the
    // windows' own σ beyond their curve. Noise pulls it out all along; a stretch of
    // the edge where the outermost samples fell unluckily deep pulls the windows'
    // curve in there only, which is no reason to leave the envelope (a clean jib's
    // leech bare for half a metre below the head lost it on the mean). Mains and
    // gennakers with 4 mm of range noise had their leeches 1.5-2.9 mm out on the
    // envelope, clean ones -1.5 to +0.7 mm. The corner curves keep the windows'
    // points: near a corner the envelope rests on few samples.
    if (e.line_spacing == 0) {
      std::vector<std::pair<double, double>> beside = stripSamples(
          every_other, [&](size_t i) { return e.curve.at(e.s[i]); }, [&](size_t i) { return e.curve.tangent(e.s[i]); },
          -strip);
      std::sort(beside.begin(), beside.end());
      const std::optional<Polynomial> envelope = lowerEnvelope(beside, spacing, degree);
      if (envelope) {
        const double lo = envelope->mid - envelope->half, hi = envelope->mid + envelope->half;
        auto offset = [&](double at) { return envelope->at(std::clamp(at, lo, hi))[0]; };
        double offset_sum = 0;
        for (const auto& [along, o] : beside) offset_sum += offset(along);
        const double width = strip - offset_sum / static_cast<double>(std::max<size_t>(1, beside.size()));
        const double density = static_cast<double>(beside.size()) / std::max(1e-12, (hi - lo) * width);
        const double gap = static_cast<double>(envelope->coeffs.rows()) / std::max(1e-12, density * (hi - lo));
        double mean_offset = 0;
        constexpr int kSteps = 100;
        std::vector<double> profile;
        for (int k = 0; k <= kSteps; ++k) {
          profile.push_back(offset(lo + (hi - lo) * k / kSteps) - gap);
          mean_offset += profile.back() / (kSteps + 1);
        }
        std::nth_element(profile.begin(), profile.begin() + kSteps / 2, profile.end());
        if (profile[kSteps / 2] >= -sigma_recess) {
          on_envelope = true;
          const std::vector<Vec3> windows_points = e.points;
          for (size_t i = 0; i < e.points.size(); ++i)
            e.points[i] += std::clamp(offset(e.s[i]) - gap, -strip, strip) * inward[i];
          fit();
          e.points = windows_points;
          sigma_recess = std::hypot(gap, mean_offset);
        }
      }
    }
  } else if (e.recess > 0) {
    for (size_t i = 0; i < e.points.size(); ++i) e.points[i] -= e.recess * inward[i];
    fit();
  }
  // A least-squares curve with degree + 1 coefficients through N points with
  // scatter σ_res is known to σ_res·√((degree + 1)/N).
  double res2 = 0;
  for (size_t i : inner) res2 += (e.points[i] - e.curve.at(e.s[i])).squaredNorm();
  const double sigma_res = std::sqrt(res2 / static_cast<double>(std::max<size_t>(1, inner.size() - 1)));
  e.scatter = sigma_res;
  const double sigma_curve = sigma_res * std::sqrt(static_cast<double>(degree + 1) / static_cast<double>(inner.size()));
  e.sigma = std::hypot(sigma_curve, sigma_recess);
  e.section_sigma = on_envelope ? sigma_recess : e.sigma;
  e.on_envelope = on_envelope;
  if (e.line_spacing > 0) {
    // The edge through the lines' ends: the samples' lower envelope along the whole
    // edge, up to the corners (the fitted curve's straight continuation is the
    // reference beyond its range; the other edge's samples near a corner lie inside
    // and do not count). Where the boundary cuts into the sail (a line left out of
    // the mesh), the 24 vertices round it lie on both sides and the inward direction
    // can turn over: those stretches are left out.
    auto reference = [&](double s_at) {
      const double sc = std::clamp(s_at, e.exclude, e.length - e.exclude);
      return Vec3(e.curve.at(sc) + (s_at - sc) * e.curve.tangent(sc));
    };
    Vec3 inward_mean = Vec3::Zero();
    for (size_t i : inner) inward_mean += inward[i];
    std::vector<size_t> facing;
    for (size_t i = 0; i < e.points.size(); i += 2)
      if (inward[i].dot(inward_mean) > 0) facing.push_back(i);
    auto reference_tangent = [&](size_t i) {
      return e.curve.tangent(std::clamp(e.s[i], e.exclude, e.length - e.exclude));
    };
    // Two line spacings beyond the curve is a stray, not a line's end.
    std::vector<std::pair<double, double>> beside = stripSamples(
        facing, [&](size_t i) { return reference(e.s[i]); }, reference_tangent, -2.0 * e.line_spacing);
    std::sort(beside.begin(), beside.end());
    const std::optional<Polynomial> envelope = lowerEnvelope(beside, spacing, degree);
    // It lies within a line spacing and a half beyond the curve through the boundary
    // and no more than half a spacing inside it; further off, the boundary is not the
    // lines' (it cut into the sail or left it) and the edge is placed as a scatter's.
    bool plausible = envelope.has_value();
    const double first = envelope ? envelope->mid - envelope->half : 0, last = envelope ? envelope->mid + envelope->half : 0;
    for (size_t i : inner) {
      if (!plausible) break;
      const double p = envelope->at(std::clamp(e.s[i], first, last))[0];
      plausible = p >= -1.5 * e.line_spacing && p <= 0.5 * e.line_spacing;
    }
    if (plausible) {
      // The curve between the corners, which the sections end on, runs along the
      // envelope; the corners keep the scatter's placement of the points near them
      // (placed from the envelope's ends, which it holds beyond the samples, heads
      // and clews moved up to 16 cm, as often worse as better).
      e.along_lines = true;
      std::vector<Vec3> pts;
      std::vector<double> at;
      for (size_t i : inner) {
        const double p = envelope->at(std::clamp(e.s[i], first, last))[0];
        const Vec3 normal = inward[i].cross(e.curve.tangent(e.s[i]));
        pts.push_back(reference(e.s[i]) + p * inward[i] + (e.points[i] - reference(e.s[i])).dot(normal) * normal);
        at.push_back(e.s[i]);
      }
      e.curve = fitEdgeCurve(pts, at, degree);
    }
  }
}

// A quadratic through an edge's points near one of its corners, as a function
// of the arc distance d from that corner (the rounded-off tip left out), with
// the 1σ scatter of its value extrapolated back to the corner.
struct CornerCurve {
  EdgeCurve curve;
  double sigma_at_corner = 0;  // m
  double from = 0, to = 0;     // the distances from the corner it was fitted over, m
  bool on_frontier = false;    // placed by the outermost samples beside it (ontoFrontier)
  // How far the other frontier fits that fit their points as well put the corner
  // sideways of this one (RMS), m: what choosing among them leaves unknown. Reported
  // in the corner's uncertainty only; sigma_at_corner weighs the crossing (placeCorner).
  double model_sigma = 0;
};

// The curve reaches max(60 boundary spacings, 5 % of the edge) from the corner.
// With `shorten_if_bent` the reach shrinks (to no less than 30 spacings) while
// the points scatter about the quadratic more than they scatter about the whole
// edge's curve and a shorter reach lowers that scatter: the edge bends more
// than a quadratic follows there. A gennaker's foot leaving the tack and curving
// away does: over 5 m of its 7 m, the quadratic put the tack 2-3 cm off along the
// luff. Near a narrow head the scatter rises for another reason (the sail is
// only a few spacings wide, and its boundary samples zigzag between the sides),
// where a shorter reach only loses the points that place the sides.
CornerCurve cornerCurve(const Edge& e, bool at_start, double spacing, int degree, bool shorten_if_bent) {
  const double skip = 3.0 * spacing, longest = std::max(60.0 * spacing, 0.05 * e.length);
  struct Fit {
    std::vector<Vec3> pts;
    std::vector<double> d;
    int used = 1;
    EdgeCurve curve;
    double sigma_res = 0;
  };
  auto fitWithin = [&](double reach) {
    Fit f;
    for (size_t i = 0; i < e.points.size(); ++i) {
      const double di = at_start ? e.s[i] : e.length - e.s[i];
      if (di >= skip && di <= std::min(skip + reach, e.length - skip)) {
        f.pts.push_back(e.points[i]);
        f.d.push_back(di);
      }
    }
    if (f.pts.size() < 6) {  // short edge: all of it
      f.pts.clear();
      f.d.clear();
      for (size_t i = 0; i < e.points.size(); ++i) {
        f.pts.push_back(e.points[i]);
        f.d.push_back(at_start ? e.s[i] : e.length - e.s[i]);
      }
    }
    // At most one coefficient per 8 points, as fitEdge: a quadratic through a dozen
    // points, extrapolated to the corner, follows a chance dip in the samples.
    f.used = std::clamp(static_cast<int>(f.pts.size()) / 8, 1, degree);
    f.curve = fitEdgeCurve(f.pts, f.d, f.used);
    double res2 = 0;
    for (size_t i = 0; i < f.pts.size(); ++i) res2 += (f.pts[i] - f.curve.at(f.d[i])).squaredNorm();
    f.sigma_res = std::sqrt(res2 / std::max(1.0, static_cast<double>(f.pts.size()) - f.used - 1));
    return f;
  };
  Fit f = fitWithin(longest);
  if (shorten_if_bent) {
    // Down to 20 spacings, where the fit still has 16 points and more: a quadratic.
    // A reach beyond the edge's end takes the same points and is passed over: on
    // a sparse gennaker (12,000 points, boundary vertices 17 cm apart) the 6.6 m
    // foot was shorter than the first reach, whose equal fit ended the search, and
    // from its tack a quadratic over the whole foot passed 16 cm off the surface
    // (the foot leaves the tack at its entry angle): 19 of 20 tacks lay 3-5.4 cm
    // out along the luff. The floor was 30 spacings, 5 m there, too long to follow
    // that turn; over 20 the tacks lay at most 2.5 cm off.
    for (double reach = longest / 1.25; reach >= 20.0 * spacing; reach /= 1.25) {
      // The RMS of n residuals spreads by a fraction 1/√(2(n − 3)): twice that is
      // still the edge's own scatter.
      const double n = static_cast<double>(f.pts.size());
      if (f.sigma_res <= e.scatter * (1.0 + 2.0 / std::sqrt(2.0 * std::max(1.0, n - 3.0)))) break;
      Fit g = fitWithin(reach);
      if (g.pts.size() == f.pts.size()) continue;
      if (g.sigma_res >= f.sigma_res) break;
      f = std::move(g);
    }
  }
  CornerCurve c;
  c.curve = f.curve;
  c.from = *std::min_element(f.d.begin(), f.d.end());
  c.to = *std::max_element(f.d.begin(), f.d.end());
  // A least-squares polynomial of degree q over evenly spread points is known at
  // the end of its range to about σ_res·(q + 1)/√N; the corner lies just beyond.
  c.sigma_at_corner = f.sigma_res * (f.used + 1) / std::sqrt(static_cast<double>(f.pts.size()));
  return c;
}

// The length of ontoFrontier's windows on corner curve c: 5 spacings, or 1/8 of
// the curve's reach (from the corner, or from where its fit began) where that is
// shorter, but no less than a spacing.
double frontierWindow(const CornerCurve& c, bool from_corner, double spacing) {
  const double start = from_corner ? 0.0 : c.from;
  return std::clamp((c.to - start) / kFrontierFewestWindows, spacing, kFrontierWindowSpacings * spacing);
}

// Which of `parts` equal parts of a window a point `along` from its centre falls in.
size_t windowPart(double along, double window, size_t parts) {
  const double f = std::clamp(along / window + 0.5, 0.0, 1.0);
  return std::min(parts - 1, static_cast<size_t>(f * static_cast<double>(parts)));
}

// How deep a corner curve's strip reaches in at distance dw from the corner
// (point p, tangent t, inward `in`), in each of `depth.size()` equal parts of a
// window along it: `strip`, or half the sail's width there where that is less
// (how far in the other edge's curve passes within that part), so that the other
// edge's samples stay out of it. One part: the least over the whole window.
void stripDepths(const CornerCurve& other, double dw, const Vec3& p, const Vec3& t, const Vec3& in, double window,
                 double strip, std::vector<double>& depth) {
  const size_t parts = depth.size();
  std::vector<double> across(parts, std::numeric_limits<double>::infinity());
  for (int i = 0; i <= 60; ++i) {
    const Vec3 q = other.curve.at(3.0 * dw * i / 60.0) - p;
    const double along = q.dot(t);
    if (std::abs(along) > 0.5 * window) continue;
    const size_t k = windowPart(along, window, parts);
    across[k] = std::min(across[k], q.dot(in));
  }
  // A part the other curve's steps passed over lies between two that it crossed.
  if (parts > 1)
    for (size_t k = 0; k < parts; ++k) {
      if (std::isfinite(across[k])) continue;
      const double lo = k > 0 ? across[k - 1] : std::numeric_limits<double>::infinity();
      const double hi = k + 1 < parts ? across[k + 1] : std::numeric_limits<double>::infinity();
      across[k] = std::min(lo, hi);
    }
  for (size_t k = 0; k < parts; ++k) depth[k] = std::min(strip, 0.5 * across[k]);
}

// A corner curve fitted through the boundary vertices carries their scatter (a
// gap each: about a centimetre on a 40,000-point gennaker), and fitted over 60
// boundary spacings it cannot follow how an edge bends on the last few metres
// to a narrow head. Extrapolated to the corner, either moves the edges'
// crossing by several times as much along the bisector: 2-5 cm there.
//
// The outermost of the many samples beside the edge place it far more sharply.
// In each window along the curve, the samples' offsets o from it (positive
// inwards) are uniform on [−δ, D], and the least of n lies a gap (D + δ)/(n + 1)
// beyond −δ on average (as frontierRecess): δ is known to about that gap, a few
// millimetres. Near a corner D is cut to half the sail's width, where the other
// edge's samples begin, in each eighth of the window along it (D then its mean
// over them: near the edge, where the least lies, the strip runs the window's
// whole length). Cut to the width at the window's narrowest, the window reaching
// into a wide corner (through which the other edge passes) held next to nothing
// and was left out; the edge was extrapolated over a window and a half, and a
// gennaker's leech lay 2.6 cm inside at its clew. Clews at 40,000 points, mean:
// mains 0.37 → 0.22 cm, gennakers 0.68 → 0.62; jib tacks 0.53 → 0.39, worst
// 1.12 → 0.75 (bench/generator-sweep). The frontier points so found take a
// quadratic or a cubic over the first m windows; each candidate is known at the
// corner to s·√(x₀ᵀ(AᵀA)⁻¹x₀) (x₀ the corner's powers, s the points' scatter:
// the least-squares prediction there). Of the candidates that fit their points
// as closely as those scatter, the one known best at the corner wins; if none
// does, the one whose misfit costs least. The points' own scatter comes from
// the second differences of their offsets, in which a smooth bend cancels and
// noise adds 6σ² (median-based, so a stray window counts little). With
// `from_corner` the windows start at the corner itself, not where the curve's
// own fit began (the samples reach closer to a wide corner than its boundary).
//
// An edge too short for 8 windows of 5 spacings takes 8 shorter ones, down to
// a spacing each. A square top's top edge, 1.2-1.5 m long, had 2 windows, too
// few, and kept its corner curve: a straight line through a dozen boundary
// vertices of a section with its own camber, which passed 8-10 cm off the
// surface at the head and met the leech 5 cm below the peak. On such an edge
// each frontier point is also taken on the surface under the curve (the mean
// plane of the 24 vertices nearest it), not on the curve: the offsets o are
// measured across the surface, so a curve that leaves it in depth would carry
// that into every point. On a longer edge the curve follows the surface to a
// millimetre, and those planes would only add their own scatter (5 mm along a
// mainsail's foot, enough to fail the residual test). In sparse scans (12,000
// points and under) most edges are that short: square-top heads and peaks, and
// the tacks of mains and jibs at 5,000 points, came out closer, the rest about
// as before.
CornerCurve ontoFrontier(const CornerCurve& c, const CornerCurve& other, const Samples& smp, double spacing,
                         bool from_corner) {
  const double start = from_corner ? 0.0 : c.from;
  const double window = frontierWindow(c, from_corner, spacing);
  if (!(window > 0)) return c;  // no spacing to step by
  const double strip = kFrontierStripSpacings * spacing;
  const bool short_edge = window < kFrontierWindowSpacings * spacing;
  std::vector<uint32_t> idx, near;
  std::vector<double> d2, near_d2;
  std::vector<double> centre, delta;
  std::vector<double> depth(kFrontierDepthParts);
  std::vector<Vec3> frontier;
  Vec3 first_in = Vec3::Zero();
  for (double dw = start + 0.5 * window; dw + 0.5 * window <= c.to + 1e-9 * window; dw += window) {
    const Vec3 p = c.curve.at(dw), t = c.curve.tangent(dw);
    const Across across_edge = acrossAt(p, p, t, smp, near, near_d2);
    const Vec3& in = across_edge.in;
    if (centre.empty()) first_in = in;  // sideways at the corner's end
    stripDepths(other, dw, p, t, in, window, strip, depth);
    double D = 0, deepest = 0;
    for (double& part : depth) {
      part = std::max(part, 0.0);
      D += part / static_cast<double>(depth.size());
      deepest = std::max(deepest, part);
    }
    if (!(D > 0.5 * spacing)) continue;
    smp.tree.withinRadius(p, std::hypot(deepest + strip, 0.5 * window), idx, d2);
    double least = std::numeric_limits<double>::infinity();
    size_t n = 0;
    for (uint32_t v : idx) {
      const double along = (smp.mesh.vertices[v] - p).dot(t);
      if (std::abs(along) > 0.5 * window) continue;
      const double o = (smp.mesh.vertices[v] - c.curve.at(dw + along)).dot(in);
      if (o > depth[windowPart(along, window, depth.size())] || o < -strip) continue;
      least = std::min(least, o);
      ++n;
    }
    if (n < 8) continue;
    centre.push_back(dw);
    delta.push_back(recessFromLeast(least, D, static_cast<double>(n)));
    frontier.push_back((short_edge ? across_edge.on_surface : p) - delta.back() * in);
  }
  constexpr size_t kFewest = 6;  // a quadratic and three degrees of freedom
  if (centre.size() < kFewest) return c;
  std::vector<double> bends;
  for (size_t j = 2; j < delta.size(); ++j) bends.push_back(std::abs(delta[j] - 2.0 * delta[j - 1] + delta[j - 2]));
  std::nth_element(bends.begin(), bends.begin() + static_cast<long>(bends.size() / 2), bends.end());
  const double scatter = 1.4826 * bends[bends.size() / 2] / std::sqrt(6.0);

  struct Candidate {
    CornerCurve curve;
    double sigma = 0;
    bool fits = false;
  };
  auto fitOver = [&](size_t m, int degree) {
    const std::vector<Vec3> pts(frontier.begin(), frontier.begin() + static_cast<long>(m));
    const std::vector<double> ds(centre.begin(), centre.begin() + static_cast<long>(m));
    Candidate k;
    k.curve.curve = fitEdgeCurve(pts, ds, degree);
    const EdgeCurve& f = k.curve.curve;
    double res2 = 0;
    Eigen::MatrixXd A(static_cast<Eigen::Index>(m), degree + 1);
    Eigen::VectorXd x0(degree + 1);
    for (size_t j = 0; j < m; ++j) {
      res2 += (pts[j] - f.at(ds[j])).squaredNorm();
      for (int e = 0; e <= degree; ++e) A(static_cast<Eigen::Index>(j), e) = std::pow((ds[j] - f.mid) / f.half, e);
    }
    for (int e = 0; e <= degree; ++e) x0[e] = std::pow(-f.mid / f.half, e);
    const double dof = static_cast<double>(m) - degree - 1;
    const double rms = std::sqrt(res2 / dof);
    const double limit = scatter * (1.0 + 2.0 / std::sqrt(2.0 * dof));  // RMS spreads by 1/√(2 dof)
    const double lever = std::sqrt(x0.dot((A.transpose() * A).ldlt().solve(x0)));
    k.fits = rms <= limit;
    k.sigma = lever * std::max(rms, scatter) * (k.fits ? 1.0 : rms / std::max(limit, 1e-12));
    k.curve.sigma_at_corner = k.sigma;
    k.curve.from = ds.front();
    k.curve.to = ds.back();
    k.curve.on_frontier = true;
    return k;
  };
  std::optional<Candidate> best;
  std::vector<Vec3> fitting_corners;
  for (size_t m = centre.size();; m = std::max(kFewest, m * 4 / 5)) {
    for (int degree : {2, 3}) {
      if (m < 2 * static_cast<size_t>(degree + 1)) continue;
      const Candidate k = fitOver(m, degree);
      if (k.fits) fitting_corners.push_back(k.curve.curve.at(0));
      if (!best || (k.fits && !best->fits) || (k.fits == best->fits && k.sigma < best->sigma)) best = k;
    }
    if (m == kFewest) break;
  }
  // The least-squares σ holds if the chosen polynomial is the edge's shape; the fits
  // that do as well over more or fewer windows, or a degree higher, say how far that
  // choice alone moves the corner. Without it clews of 40,000-point gennakers and
  // jibs lay 1.7 of their σ off (RMS), with it 1.05-1.2 (bench/generator-sweep).
  if (best->fits && fitting_corners.size() > 1) {
    const Vec3 chosen = best->curve.curve.at(0);
    double ss = 0;
    for (const Vec3& q : fitting_corners) ss += std::pow((q - chosen).dot(first_in), 2);
    best->curve.model_sigma = std::sqrt(ss / static_cast<double>(fitting_corners.size() - 1));
  }
  return best->curve;
}

// A wide corner whose edge bends more than ontoFrontier's windows follow (a
// gennaker's foot leaving the tack) kept its shortened quadratic through the
// boundary vertices, which carry a gap's scatter each (about a centimetre at
// 40,000 points) and follow a notch where few samples fell near the edge: a
// tack came out 4 cm up the luff, the upper twist 0.19° off. All the samples
// beside the curve, from the corner to its reach, place it sharper: their lower
// envelope, a quadratic relative to the curve lying beyond every one of them, as
// fitEdge's for a whole edge, moved out by the band (q + 1)/(ρ L) it leaves on
// average. A notch only loosens the constraints where it lies. Extrapolated to
// the corner a quadratic spreads several times its interior error either way;
// over uniform scatters in simulation (1.5 m, 780 points/m²) the envelope's
// value there spread 7 mm against the windows' 12. Clean 40,000-point gennakers'
// tacks: 1.25 → 0.64 cm RMS (0.5 along the foot), 60,000: 1.01 → 0.66, worst
// 4.31 → 1.77 cm. The curve's σ at the corner stays its least-squares one, a
// bound on this. Below 12 windows of a spacing, or when the programme has no
// optimum, the curve stays as it was.
CornerCurve ontoEnvelope(const CornerCurve& c, const CornerCurve& other, const Samples& smp, double spacing) {
  const double strip = kFrontierStripSpacings * spacing;
  std::vector<uint32_t> idx, near;
  std::vector<double> d2, near_d2;
  std::vector<std::pair<double, double>> beside;
  std::vector<double> centre, one_depth(1);
  std::vector<Vec3> at, in;
  double width_sum = 0;
  for (double dw = 0.5 * spacing; dw + 0.5 * spacing <= c.to + 1e-9 * spacing; dw += spacing) {
    const Vec3 p = c.curve.at(dw), t = c.curve.tangent(dw);
    const Vec3 inward = acrossAt(p, p, t, smp, near, near_d2).in;
    stripDepths(other, dw, p, t, inward, spacing, strip, one_depth);
    const double D = one_depth[0];
    if (!(D > 0.5 * spacing)) continue;
    centre.push_back(dw);
    at.push_back(p);
    in.push_back(inward);
    width_sum += D;
    smp.tree.withinRadius(p, std::hypot(D + strip, 0.5 * spacing), idx, d2);
    for (uint32_t v : idx) {
      const double along = (smp.mesh.vertices[v] - p).dot(t);
      if (along < -0.5 * spacing || along >= 0.5 * spacing) continue;
      const double o = (smp.mesh.vertices[v] - c.curve.at(dw + along)).dot(inward);
      if (o > D || o < -strip) continue;
      beside.emplace_back(dw + along, o);
    }
  }
  if (centre.size() < 12) return c;
  std::sort(beside.begin(), beside.end());
  const std::optional<Polynomial> envelope = lowerEnvelope(beside, spacing, 2);
  if (!envelope) return c;
  const double lo = envelope->mid - envelope->half, hi = envelope->mid + envelope->half;
  const double length = centre.back() - centre.front() + spacing;
  const double density = static_cast<double>(beside.size()) / std::max(1e-12, width_sum * spacing);
  const double gap = static_cast<double>(envelope->coeffs.rows()) / std::max(1e-12, density * length);
  std::vector<Vec3> pts;
  for (size_t j = 0; j < centre.size(); ++j)
    pts.push_back(at[j] + (envelope->at(std::clamp(centre[j], lo, hi))[0] - gap) * in[j]);
  CornerCurve k = c;
  k.curve = fitEdgeCurve(pts, centre, 2);
  k.from = centre.front();
  k.to = centre.back();
  return k;
}

// Where two edges meet, and how they arrive there.
struct Meeting {
  Vec3 point = Vec3::Zero();
  Vec3 outward = Vec3::Zero();  // unit, out of the sail along the corner's bisector
  double angle_rad = 0;         // interior angle between the two edges
  double sigma_along_m = 0;     // 1σ of `point` along `outward`
  // Each edge's unit normal into the sail (in the corner's plane) and its 1σ
  // sideways uncertainty at the corner.
  Vec3 inward_a = Vec3::Zero(), inward_b = Vec3::Zero();
  double side_a_m = 0, side_b_m = 0;
  // What the choice among equally fitting frontier curves leaves unknown (CornerCurve::
  // model_sigma), along and across the bisector, at a wide corner: reported, not weighed.
  double model_along_m = 0, model_across_m = 0;
};

// How far a corner curve turns over its first frontier window (from where it
// was fitted), radians.
double turnOverWindow(const CornerCurve& c, double window) {
  const Vec3 t0 = c.curve.tangent(c.from), t1 = c.curve.tangent(c.from + window);
  return std::acos(std::clamp(t0.dot(t1), -1.0, 1.0));
}

// The closest pair of points of the two edges' corner curves (quadratics in the
// distance from the corner, extrapolated back to it).
//
// Narrower corners than 60° (a head) move both curves onto the samples' frontier
// (ontoFrontier), and then, where both whole edges rest on their samples' lower
// envelope (a clean scatter: fitEdge keeps it only while noise across the edge
// does not pull it out), onto the lower envelope beside each frontier curve
// (ontoEnvelope). The windows' estimates err one way far more than the other (a
// window whose outermost sample fell unluckily deep lies several gaps inside), and
// near the head the windows are short and few: a clean jib's leech had its first
// window 1.6 cm inside and its quadratic 2.6 cm inside at the head, which came out
// 5.2 cm low; on the envelope, 0.7 cm. Clean heads, RMS over 20-30 seeds at 40,000
// points: jibs on a raked forestay 1.86 → 0.86 cm, gennakers 1.20 → 0.99 cm
// (bench/independent-sails).
//
// Wider corners (a tack, a clew, a square head) let their curves shorten where an
// edge bends; then, if neither edge turns more than 0.08 rad
// over a frontier window, both move onto the frontier too, with windows from the
// corner itself over the unshortened reach. The boundary rounds off a wide corner
// over half a metre and more: a gennaker's foot lay 2-5 cm inside its clew there,
// and 2-3 of 90 clews came out 3.3-4.8 cm off (now at most 1.5 cm). A foot
// leaving the tack at its entry angle turns 0.10-0.11 rad over 5 spacings, more
// than the windows' curve follows: on the frontier it put the tack up to 3.3 cm
// off and the upper twist 0.24° off, so such a corner keeps its shortened
// quadratics, moved onto their samples' lower envelope (ontoEnvelope; feet turn
// 0.05-0.06 rad at the clew, luffs and leeches 0.01-0.03).
// The window is the one ontoFrontier would use on that edge (shorter on a short
// edge): a square top's 2.2 m top edge, cambered, turned 0.085-0.093 rad over 5
// spacings but less over its own windows, and had kept quadratics that put head
// and peak 4-6 cm low. In sparse scans most edges are short, and a foot may turn
// up to 0.08 rad over its shorter window where over 5 spacings it would be
// refused: tacks and clews at 5,000-12,000 points came out closer on the whole
// (the worst run worse in 2 of 16 sets of 20).
Meeting meetEdges(const Edge& a, bool a_start, const Edge& b, bool b_start, double spacing, const Samples& smp) {
  const double range = 3.0 * spacing + std::max({60.0 * spacing, 0.05 * a.length, 0.05 * b.length});
  auto closest = [&](const CornerCurve& ca, const CornerCurve& cb) {
    double best = std::numeric_limits<double>::infinity(), sa = 0, sb = 0;
    double r = range;
    for (int level = 0; level < 6; ++level) {
      const double ma = sa, mb = sb;
      for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j) {
          const double ta = ma + r * i / 10.0, tb = mb + r * j / 10.0;
          const double dd = (ca.curve.at(ta) - cb.curve.at(tb)).squaredNorm();
          if (dd < best) {
            best = dd;
            sa = ta;
            sb = tb;
          }
        }
      r /= 5.0;
    }
    return std::make_pair(sa, sb);
  };
  auto angleAt = [](const CornerCurve& ca, double sa, const CornerCurve& cb, double sb) {
    return std::acos(std::clamp(ca.curve.tangent(sa).dot(cb.curve.tangent(sb)), -1.0, 1.0));
  };
  CornerCurve ca = cornerCurve(a, a_start, spacing, 2, false), cb = cornerCurve(b, b_start, spacing, 2, false);
  auto [sa, sb] = closest(ca, cb);
  const bool wide = angleAt(ca, sa, cb, sb) >= kPi / 3.0;
  if (wide) {
    constexpr double kFollowedTurnRad = 0.08;
    const CornerCurve whole_a = ca, whole_b = cb;  // unshortened: the frontier's reach
    ca = cornerCurve(a, a_start, spacing, 2, true);
    cb = cornerCurve(b, b_start, spacing, 2, true);
    const bool followed = turnOverWindow(ca, frontierWindow(whole_a, true, spacing)) < kFollowedTurnRad &&
        turnOverWindow(cb, frontierWindow(whole_b, true, spacing)) < kFollowedTurnRad;
    if (!followed) {
      const CornerCurve shortened_a = ca, shortened_b = cb;
      ca = ontoEnvelope(shortened_a, shortened_b, smp, spacing);
      cb = ontoEnvelope(shortened_b, shortened_a, smp, spacing);
    }
    if (followed) {
      const CornerCurve fa = ontoFrontier(whole_a, whole_b, smp, spacing, true);
      const CornerCurve fb = ontoFrontier(whole_b, whole_a, smp, spacing, true);
      if (fa.on_frontier && fb.on_frontier) {
        ca = fa;
        cb = fb;
      }
    }
  } else {
    CornerCurve fa = ontoFrontier(ca, cb, smp, spacing, false), fb = ontoFrontier(cb, ca, smp, spacing, false);
    // Once more from the frontier curves, over the corner curves' reach. A window's
    // outermost sample is measured from the curve, and where that curve strays from
    // the edge within the window (the corner curve through boundary vertices, a
    // window 0.8 m long at 12,000 points) the least offset is the edge's furthest
    // excursion there, not its place: a sparse gennaker's first leech window lay
    // 2.7 cm out, a cubic followed it and the head came out 5 cm low. Measured from
    // the frontier curve, the edge runs nearly straight in each window. Heads over
    // 3 cm: 12,000-point gennakers 12 → 7 of 20, 20,000-point 2 → 1, 12,000-point
    // mains 2 → 1; at 40,000 points unchanged (bench/generator-sweep/README.md).
    auto again = [&](const CornerCurve& f, const CornerCurve& c, const CornerCurve& other) {
      if (!f.on_frontier) return f;
      CornerCurve r = f;
      r.from = c.from;
      r.to = c.to;
      const CornerCurve g = ontoFrontier(r, other, smp, spacing, false);
      return g.on_frontier ? g : f;
    };
    const CornerCurve first_a = fa;
    fa = again(fa, ca, fb);
    fb = again(fb, cb, first_a);
    ca = fa;
    cb = fb;
    if (a.on_envelope && b.on_envelope) {
      ca = ontoEnvelope(fa, fb, smp, spacing);
      cb = ontoEnvelope(fb, fa, smp, spacing);
    }
  }
  std::tie(sa, sb) = closest(ca, cb);
  Meeting m;
  m.point = 0.5 * (ca.curve.at(sa) + cb.curve.at(sb));
  // Directions into the sail along each edge (increasing distance from the corner).
  const Vec3 ta = ca.curve.tangent(sa), tb = cb.curve.tangent(sb);
  m.angle_rad = std::acos(std::clamp(ta.dot(tb), -1.0, 1.0));
  const Vec3 bis = ta + tb;
  m.outward = bis.norm() > 1e-9 ? Vec3(-bis.normalized()) : Vec3::Zero();
  // Shifting the two edges sideways by ε_a and ε_b moves their crossing along
  // the bisector by (ε_a + ε_b) / (2 sin(angle / 2)).
  const double half = std::max(0.5 * m.angle_rad, 1e-3);
  // Each edge's sideways uncertainty at the corner: a frontier curve's own; else
  // its corner curve's, the whole edge's, and half its recess: the edge was moved
  // out by its recess averaged along it, and where the sail narrows to a corner
  // the samples thin out differently, so how far the edge lies beyond them there
  // is known only roughly.
  auto side = [](const CornerCurve& c, const Edge& e) {
    return c.on_frontier ? c.sigma_at_corner : std::hypot(c.sigma_at_corner, e.sigma, 0.5 * e.recess);
  };
  const double side_a = side(ca, a), side_b = side(cb, b);
  m.sigma_along_m = std::hypot(side_a, side_b) / (2.0 * std::sin(half));
  const Vec3 across_a = tb - tb.dot(ta) * ta, across_b = ta - ta.dot(tb) * tb;
  if (across_a.norm() > 1e-9 && across_b.norm() > 1e-9) {
    m.inward_a = across_a.normalized();
    m.inward_b = across_b.normalized();
  }
  m.side_a_m = side_a;
  m.side_b_m = side_b;
  // At a narrow corner that choice moves the crossing far along the bisector, where
  // the outermost samples bound the corner anyway (placeCorner): there the added
  // term put heads' σ at twice their errors (RMS), so it counts at wide corners only.
  if (wide) {
    const double model = std::hypot(ca.model_sigma, cb.model_sigma);
    m.model_along_m = model / (2.0 * std::sin(half));
    m.model_across_m = model / (2.0 * std::cos(std::min(half, 1.4)));
  }
  return m;
}

// The sail's surface around a corner: the quadratic height field of the mesh
// vertices around it (at least 40 of them, within 10-160 boundary spacings).
// Close to the corner it reaches the few spacings beyond the samples far better
// than the edges' corner curves, which extrapolate their own bend.
struct HeightField {
  Vec3 origin = Vec3::Zero(), normal = Vec3::UnitZ(), eu = Vec3::UnitX(), ev = Vec3::UnitY();
  double radius = 1;                                     // (u, v) are in units of it
  Eigen::Matrix<double, 6, 1> h = Eigen::Matrix<double, 6, 1>::Zero();
  double rms_m = 0;                                      // the vertices' scatter about it
  // Signed height of q over the field, along `normal`.
  double offset(const Vec3& q) const {
    const Vec3 d = q - origin;
    const double u = d.dot(eu) / radius, v = d.dot(ev) / radius;
    return d.dot(normal) - (h[0] + h[1] * u + h[2] * v + h[3] * u * u + h[4] * u * v + h[5] * v * v);
  }
};

std::optional<HeightField> heightFieldAround(const Vec3& c, const Mesh& mesh, const PointGrid& tree, double spacing) {
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  double radius = 10.0 * spacing;
  for (int i = 0; i < 5; ++i, radius *= 2.0) {
    tree.withinRadius(c, radius, idx, d2);
    if (idx.size() >= 40) break;
  }
  if (idx.size() < 40) return std::nullopt;
  HeightField f;
  f.origin = c;
  f.radius = radius;
  // Any in-plane axes serve: the full quadratic is the same in every rotation of them.
  f.normal = fitPlane(mesh.vertices, idx).normal;
  f.eu = f.normal.unitOrthogonal();
  f.ev = f.normal.cross(f.eu);
  Eigen::MatrixXd A(static_cast<Eigen::Index>(idx.size()), 6);
  Eigen::VectorXd z(static_cast<Eigen::Index>(idx.size()));
  for (size_t i = 0; i < idx.size(); ++i) {
    const Vec3 d = mesh.vertices[idx[i]] - c;
    const double u = d.dot(f.eu) / radius, v = d.dot(f.ev) / radius;
    A.row(static_cast<Eigen::Index>(i)) << 1, u, v, u * u, u * v, v * v;
    z[static_cast<Eigen::Index>(i)] = d.dot(f.normal);
  }
  f.h = A.colPivHouseholderQr().solve(z);
  if (!f.h.allFinite()) return std::nullopt;
  f.rms_m = std::sqrt((A * f.h - z).squaredNorm() / std::max<double>(1.0, static_cast<double>(idx.size()) - 6));
  return f;
}

// The direction from `corner` to the point a tenth of edge e's length along it
// (from its start when at_start, else from its end): how the sail's samples open
// from a corner, which the corner curves' own tangents where they meet, extrapolated
// past the samples, may not show (they can close in to parallel).
Vec3 edgeChord(const Edge& e, bool at_start, const Vec3& corner, double spacing) {
  const double l = std::clamp(0.1 * e.length, std::min(e.exclude + spacing, 0.5 * e.length), 0.5 * e.length);
  return Vec3(e.curve.at(at_start ? l : e.length - l) - corner).normalized();
}

// At a narrow corner (the head of most sails) the crossing of the two edges is
// poorly placed along the bisector, while the samples say where the sail at least
// reaches: the corner lies at or beyond the outermost sample, and a wedge of
// length L beyond it, sampled at ρ points/m², stays empty with probability
// exp(−ρ·L²·tan(angle/2)) (the wedge's area). The corner is placed at the mean
// of the crossing's Gaussian times that probability, for L ≥ 0, and known to
// that product's standard deviation.
struct PlacedCorner {
  Vec3 point = Vec3::Zero();
  double sigma_m = 0;  // 1σ along the bisector
};
PlacedCorner placeCorner(const Meeting& m, const Mesh& mesh, const PointGrid& tree, const std::vector<Vec3>& loose,
                         double density, double reach, double spacing, double chord_angle_rad) {
  if (m.outward.isZero() || !(density > 0) || !(m.sigma_along_m > 0)) return {m.point, m.sigma_along_m};
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  tree.withinRadius(m.point, reach, idx, d2);
  double extreme = -std::numeric_limits<double>::infinity();
  for (uint32_t v : idx) extreme = std::max(extreme, (mesh.vertices[v] - m.point).dot(m.outward));
  // No sample within reach: the crossing lies far out beyond the sail, as where
  // two nearly parallel edges meet (a square top whose peak turned too little to
  // be found as a corner put its head 3 m above the sail). The outermost sample
  // along the bisector, within reach of it sideways, bounds it then.
  if (idx.empty())
    for (const Vec3& v : mesh.vertices) {
      const Vec3 d = v - m.point;
      const double along = d.dot(m.outward);
      if ((d - along * m.outward).squaredNorm() <= reach * reach) extreme = std::max(extreme, along);
    }
  if (!std::isfinite(extreme)) return {m.point, m.sigma_along_m};
  // A sample the mesh left out (its triangles' edges too long: a lone sample
  // near a narrow tip) still says how far the sail reaches, if it lies inside
  // both edges and on the surface.
  if (!loose.empty() && !m.inward_a.isZero()) {
    const std::optional<HeightField> field = heightFieldAround(m.point, mesh, tree, spacing);
    for (const Vec3& q : loose) {
      const Vec3 d = q - m.point;
      if (!field || d.squaredNorm() > reach * reach) continue;
      const bool inside = d.dot(m.inward_a) >= -2.0 * m.side_a_m && d.dot(m.inward_b) >= -2.0 * m.side_b_m;
      // The smoothed points lie within a few scatters of the field; the floor
      // stands in where the scatter is next to nothing (a clean scan).
      const bool on_surface = std::abs(field->offset(q)) <= std::max(3.0 * field->rms_m, 0.2 * spacing);
      if (inside && on_surface) extreme = std::max(extreme, d.dot(m.outward));
    }
  }
  // The wedge opens at least as the edges' chords from the crossing do: a tunnel
  // main's corner curves met parallel at its 20° head (the tangents' angle 0.1°),
  // which left the tip's gap unbounded and put the head 24 cm beyond its samples.
  // (Edges parallel to the last bit still leave a wedge: the half angle is floored
  // as meetEdges floors it, so that λ > 0.)
  const double lambda = density * std::tan(std::clamp(0.5 * std::max(m.angle_rad, chord_angle_rad), 1e-3, 1.4));
  const double gap_scale = 1.0 / std::sqrt(lambda);  // typical empty tip length, m
  const double s = m.sigma_along_m;
  // A crossing many of its σ and of the tip's gaps beyond every sample comes from
  // corner curves extrapolated far past their data (σ holds at the corner they
  // were fitted to, not metres out). The samples alone place it then: at the mean
  // empty gap, 1 / √(π λ), beyond the outermost (the gap's spread under e^(−λ g²)
  // is √(1/2 − 1/π) / √λ).
  if (extreme < -6.0 * (s + gap_scale))
    return {m.point + (extreme + 1.0 / std::sqrt(kPi * lambda)) * m.outward,
            std::sqrt(0.5 - 1.0 / kPi) * gap_scale};
  const double lo = extreme, hi = std::max(extreme, 0.0) + 6.0 * std::max(s, gap_scale);
  constexpr int kSteps = 2000;
  double wsum = 0, xsum = 0, x2sum = 0;
  for (int i = 1; i <= kSteps; ++i) {
    const double x = lo + (hi - lo) * i / kSteps;  // corner position along the bisector
    const double gap = x - extreme;
    const double w = std::exp(-0.5 * (x / s) * (x / s) - lambda * gap * gap);
    wsum += w;
    xsum += w * x;
    x2sum += w * x * x;
  }
  if (!(wsum > 0)) return {m.point + std::max(extreme, 0.0) * m.outward, s};
  const double mean = xsum / wsum;
  return {m.point + mean * m.outward, std::sqrt(std::max(0.0, x2sum / wsum - mean * mean))};
}

// The edges' crossing is placed well within the sail's surface but not in depth:
// there each edge's corner curve extrapolates its own bend (a foot leaves the
// tack at the entry angle and curves away), and a jib's tack came out 3 cm off
// the surface. The corner lies on the surface: it moves onto the height field
// along its normal.
Vec3 ontoSurface(const Vec3& c, const Mesh& mesh, const PointGrid& tree, double spacing) {
  const std::optional<HeightField> f = heightFieldAround(c, mesh, tree, spacing);
  return f ? Vec3(c + f->h[0] * f->normal) : c;
}

// The area between two polylines running the same way (an edge's sampled
// boundary `a` and its outline `b`): triangles zipped between them by their arc
// fractions, each counted outwards where `b` lies to the right of `a` seen from
// `up` (outside the sail, for a boundary running anticlockwise about `up`) and
// inwards where to the left (noise across an edge leaves samples beyond it).
double ribbonArea(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& up) {
  if (a.size() < 2 || b.size() < 2) return 0;
  auto fractions = [](const std::vector<Vec3>& line) {
    std::vector<double> f(line.size(), 0.0);
    for (size_t i = 1; i < line.size(); ++i) f[i] = f[i - 1] + (line[i] - line[i - 1]).norm();
    for (double& x : f) x /= std::max(f.back(), 1e-12);
    return f;
  };
  const std::vector<double> fa = fractions(a), fb = fractions(b);
  double area = 0;
  for (size_t i = 0, j = 0; i + 1 < a.size() || j + 1 < b.size();) {
    // Twice the triangle's vector area: it points against `up` when b lies to the right.
    Vec3 c;
    if (j + 1 >= b.size() || (i + 1 < a.size() && fa[i + 1] <= fb[j + 1])) {
      c = (a[i + 1] - a[i]).cross(b[j] - a[i]);
      ++i;
    } else {
      c = (b[j + 1] - a[i]).cross(b[j] - a[i]);
      ++j;
    }
    area -= 0.5 * std::copysign(c.norm(), c.dot(up));
  }
  return area;
}

// How far the beam's footprint reaches from its axis across the surface at p
// (unit normal n) in the surface direction w (unit), for a scanner at `origin`: the
// beam's radius there, exit/2 + range·divergence/2, and in the plane of incidence
// that over cos(incidence) (capped at 80°, beyond which nothing returns).
double footprintReach(const OutlineParams& p, const Vec3& origin, const Vec3& at, const Vec3& n, const Vec3& w) {
  const Vec3 d = at - origin;
  const double range = d.norm();
  if (!(range > 0)) return 0;
  const double radius = 0.5 * p.beam_exit_diameter_m + 0.5 * range * p.beam_divergence_rad;
  const Vec3 ray = d / range;
  const double cos_i = std::max(std::abs(ray.dot(n)), std::cos(80.0 * kPi / 180.0));
  const Vec3 along = ray - ray.dot(n) * n;  // the ray's direction in the surface
  const double c = along.norm() > 1e-9 ? w.dot(along.normalized()) : 0.0;
  const double tan2 = (1.0 - cos_i * cos_i) / (cos_i * cos_i);
  return radius * std::sqrt(1.0 + tan2 * c * c);
}

// How far a corner moves when each of its edges a and b (meeting at `corner`, each
// starting there when *_start) moves out by the beam's footprint: x with x·(−in_a) =
// s_a and x·(−in_b) = s_b, in the corner's plane (far along the bisector at a narrow
// head: a footprint of 1.5 cm moved a 20° head of a tunnel main 9 cm). The edges'
// directions are taken over a tenth of their length: the corner curves' own tangents
// where they meet, extrapolated past the samples, may close in (a tunnel main's 20°
// head met at 3.7°, which moved it 67 cm). Zero where the edges are parallel.
Vec3 footprintShift(const OutlineParams& p, const Vec3& scanner, const Vec3& corner, const Edge& a, bool a_start,
                    const Edge& b, bool b_start, double spacing) {
  const Vec3 ta = edgeChord(a, a_start, corner, spacing), tb = edgeChord(b, b_start, corner, spacing);
  const Vec3 across_a = tb - tb.dot(ta) * ta, across_b = ta - ta.dot(tb) * tb;
  const Vec3 plane_normal = ta.cross(tb);
  if (!(plane_normal.norm() > 1e-3 && across_a.norm() > 1e-6 && across_b.norm() > 1e-6)) return Vec3::Zero();
  const Vec3 n = plane_normal.normalized(), in_a = across_a.normalized(), in_b = across_b.normalized();
  const double s_a = footprintReach(p, scanner, corner, n, -in_a);
  const double s_b = footprintReach(p, scanner, corner, n, -in_b);
  const double cc = in_a.dot(in_b), det = std::max(1.0 - cc * cc, 1e-6);
  return ((-s_a + cc * s_b) * in_a + (-s_b + cc * s_a) * in_b) / det;
}

// The edge from corner to corner: the fitted curve between the excluded ends.
std::vector<Vec3> edgePolyline(const Edge& e, const Vec3& first, const Vec3& last, double step) {
  std::vector<Vec3> out{first};
  const double from = e.exclude, to = e.length - e.exclude;
  const size_t n = std::max<size_t>(2, static_cast<size_t>(std::ceil((to - from) / std::max(step, 1e-6))) + 1);
  for (size_t i = 0; i < n; ++i)
    out.push_back(e.curve.at(from + (to - from) * static_cast<double>(i) / static_cast<double>(n - 1)));
  out.push_back(last);
  return out;
}

}  // namespace

double polylineLength(const std::vector<Vec3>& line) {
  double len = 0;
  for (size_t i = 1; i < line.size(); ++i) len += (line[i] - line[i - 1]).norm();
  return len;
}

Vec3 pointAtFraction(const std::vector<Vec3>& line, double fraction) {
  if (line.empty()) throw InvalidInput("[pointAtFraction] empty polyline");
  if (line.size() == 1) return line[0];
  const double target = std::clamp(fraction, 0.0, 1.0) * polylineLength(line);
  double acc = 0;
  for (size_t i = 1; i < line.size(); ++i) {
    const double seg = (line[i] - line[i - 1]).norm();
    if (acc + seg >= target && seg > 0) return line[i - 1] + (target - acc) / seg * (line[i] - line[i - 1]);
    acc += seg;
  }
  return line.back();
}

void checkOutlineParams(const OutlineParams& p) {
  if (!(p.beam_exit_diameter_m >= 0) || !(p.beam_divergence_rad >= 0) || p.beam_exit_diameter_m > 1 ||
      p.beam_divergence_rad > 0.5)
    throw InvalidInput("[extractOutline] beam_exit_diameter_m must be in [0, 1] and beam_divergence_rad in [0, 0.5] (got " +
                       formatFixed(p.beam_exit_diameter_m, 4) + ", " + formatFixed(p.beam_divergence_rad, 4) + ")");
  if (p.corners != 0 && p.corners != 3 && p.corners != 4)
    throw InvalidInput("[extractOutline] corners must be 0 (auto), 3 or 4 (got " + std::to_string(p.corners) + ")");
  if (!p.design_lengths_m.empty() && p.design_lengths_m.size() != 3)
    throw InvalidInput("[extractOutline] design_lengths_m must be [luff, leech, foot] (got " +
                       std::to_string(p.design_lengths_m.size()) + " values)");
}

SailOutline extractOutline(const Mesh& mesh, const OutlineParams& p, const std::vector<Vec3>& loose_points,
                           double sample_density_per_m2, const std::optional<Vec3>& scanner) {
  if (mesh.triangles.empty()) throw InvalidInput("[extractOutline] empty mesh");
  checkOutlineParams(p);
  const bool beam_given = p.beamGiven();
  const bool footprint = beam_given && scanner.has_value() && !p.edges_against_sky;
  SailOutline out;
  if (beam_given && !scanner && !p.edges_against_sky)
    out.warnings.push_back("the beam's footprint is given but not where the scanner stood (the cloud has no viewpoint): "
                           "the edges are not moved out by it");
  const std::vector<uint32_t> loop_idx = outerBoundaryLoop(mesh);
  std::vector<Vec3>& pts = out.boundary;
  for (uint32_t v : loop_idx) pts.push_back(mesh.vertices[v]);
  const size_t n = pts.size();
  std::vector<double> cum(n, 0.0), seg(n);
  for (size_t i = 0; i < n; ++i) seg[i] = (pts[(i + 1) % n] - pts[i]).norm();
  for (size_t i = 1; i < n; ++i) cum[i] = cum[i - 1] + seg[i - 1];
  const double total = cum[n - 1] + seg[n - 1];
  {
    std::vector<double> s = seg;
    std::nth_element(s.begin(), s.begin() + n / 2, s.end());
    out.boundary_spacing_m = s[n / 2];
  }
  const double w = p.corner_window_m > 0 ? p.corner_window_m : 0.01 * total;

  // The loop's normal (Newell's: the sum of its edges' cross products, twice the
  // area the loop encloses), so that the loop turns anticlockwise about it.
  Vec3 loop_normal = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) loop_normal += pts[i].cross(pts[(i + 1) % n]);
  // Whether the loop, arriving along `in` and leaving along `out`, turns outwards.
  auto outwards = [&](const Vec3& in, const Vec3& out) { return in.cross(out).dot(loop_normal) >= 0; };
  // Turning angle over arms of length `arm`; at a corner it approaches the exterior
  // angle. Negative where the loop turns inwards: a sail's corners all bulge out,
  // and a notch in a sparse edge (a triangle the long-edge limit left out) turns as
  // sharply the other way; one 9 cm deep in a 5,000-point mainsail's leech turned
  // 68° and was taken for the tack.
  auto turnAt = [&](size_t i, double arm) {
    const Vec3 a = pts[i] - loopPointAt(pts, cum, total, cum[i] - arm);
    const Vec3 b = loopPointAt(pts, cum, total, cum[i] + arm) - pts[i];
    const double c = a.dot(b) / std::max(1e-12, a.norm() * b.norm());
    const double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
    return outwards(a, b) ? angle : -angle;
  };
  std::vector<double> turn(n);
  for (size_t i = 0; i < n; ++i) turn[i] = turnAt(i, w);
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return turn[a] > turn[b]; });
  const double min_sep = std::max(2.5 * w, 0.025 * total);
  auto arcDist = [&](size_t a, size_t b) {
    const double d = std::abs(cum[a] - cum[b]);
    return std::min(d, total - d);
  };
  std::vector<size_t> picked;
  for (size_t i : order) {
    if (picked.size() == 4 || turn[i] <= 0) break;
    bool far = true;
    for (size_t j : picked) far = far && arcDist(i, j) >= min_sep;
    if (far) picked.push_back(i);
  }
  if (picked.size() < 3)
    throw AnalysisError("[extractOutline] the boundary (" + formatFixed(total, 2) + " m) has fewer than 3 distinct corners");
  size_t count = p.corners;
  if (count == 0) {
    // A 4th corner (picked min_sep = 2.5 windows from the others) must keep
    // turning sharply at twice the scale: a square head is a real edge, not a
    // kink beside the head of a triangular sail nor a local notch in a noisy
    // edge. Over main, jib, gennaker and square top at 5,000-40,000 points the
    // triangles' 4th pick turned 7-39° over the window but at most 17° over twice
    // it; square heads turned 51-78° and 61-92°. A sparse square top's peak,
    // rounded off over a few samples, can turn as little as 34° over the window
    // (44° over twice it): over the window half the limit is enough.
    count = picked.size() == 4 && turn[picked[3]] >= 0.5 * p.min_fourth_corner_deg &&
                    turnAt(picked[3], 2.0 * w) >= p.min_fourth_corner_deg
                ? 4
                : 3;
    if (count == 4) {
      // A square head's two corners both stand near the top of the sail, not
      // halfway up an edge (a kink from a few mast points at the luff).
      std::vector<double> z;
      for (size_t c : picked) z.push_back(pts[c].z());
      std::sort(z.begin(), z.end());
      if (z[2] - z[1] < 0.6 * (z[3] - z[0])) count = 3;
    }
  }
  if (picked.size() < count)
    throw AnalysisError("[extractOutline] asked for " + std::to_string(count) + " corners, found " +
                        std::to_string(picked.size()));
  picked.resize(count);
  // Refine: the apex is the vertex farthest from the chord across the corner, on
  // its outer side (a notch beside a rounded corner can reach farther inwards).
  for (size_t& c : picked) {
    const Vec3 a = loopPointAt(pts, cum, total, cum[c] - w), b = loopPointAt(pts, cum, total, cum[c] + w);
    const Vec3 ab = (b - a).normalized();
    double best = -1;
    size_t best_i = c;
    for (size_t i = 0; i < n; ++i) {
      if (arcDist(i, c) > w || !outwards(pts[i] - a, b - pts[i])) continue;
      const Vec3 d = pts[i] - a;
      const double dist = (d - ab * d.dot(ab)).norm();
      if (dist > best) {
        best = dist;
        best_i = i;
      }
    }
    c = best_i;
  }

  // Name the corners in the boat frame: head (and peak) highest, tack forward of clew.
  std::vector<size_t> by_z = picked;
  std::sort(by_z.begin(), by_z.end(), [&](size_t a, size_t b) { return pts[a].z() > pts[b].z(); });
  size_t head, tack, clew, peak = 0;
  auto forwardFirst = [&](size_t a, size_t b) { return pts[a].x() >= pts[b].x() ? std::make_pair(a, b) : std::make_pair(b, a); };
  if (count == 4) {
    std::tie(head, peak) = forwardFirst(by_z[0], by_z[1]);
    std::tie(tack, clew) = forwardFirst(by_z[2], by_z[3]);
  } else {
    head = by_z[0];
    std::tie(tack, clew) = forwardFirst(by_z[1], by_z[2]);
  }
  out.tack = pts[tack];
  out.clew = pts[clew];
  out.head = pts[head];
  out.has_peak = count == 4;
  if (out.has_peak) out.peak = pts[peak];
  out.corner_turn_deg = {turn[tack], turn[clew], turn[head]};
  if (out.has_peak) out.corner_turn_deg.push_back(turn[peak]);

  // Walk the loop between two corners, the way that does not pass another corner.
  auto edge = [&](size_t from, size_t to) {
    for (int dir : {1, -1}) {
      std::vector<Vec3> line{pts[from]};
      bool blocked = false;
      for (size_t i = (from + n + dir) % n;; i = (i + n + dir) % n) {
        line.push_back(pts[i]);
        if (i == to) break;
        if (std::find(picked.begin(), picked.end(), i) != picked.end()) {
          blocked = true;
          break;
        }
      }
      if (!blocked) return line;
    }
    throw AnalysisError("[extractOutline] corners are not in sail order along the boundary");
  };
  // Fit each edge, move it out to where the surface really ends, and place the
  // corners where neighbouring edges meet (a sharp corner itself is never sampled).
  const std::vector<Vec3> normals = vertexNormals(mesh);
  // Cells about three boundary spacings wide: the 24 nearest vertices of a boundary point lie within two or so.
  const PointGrid tree(mesh.vertices, 3.0 * std::max(out.boundary_spacing_m, 1e-6));
  const Samples samples{mesh, normals, tree};
  auto makeEdge = [&](size_t from, size_t to) {
    Edge e;
    e.points = edge(from, to);
    e.s.assign(e.points.size(), 0.0);
    for (size_t i = 1; i < e.points.size(); ++i) e.s[i] = e.s[i - 1] + (e.points[i] - e.points[i - 1]).norm();
    fitEdge(e, samples, out.boundary_spacing_m);
    return e;
  };
  const Edge luff = makeEdge(tack, head), foot = makeEdge(tack, clew);
  const Edge leech = makeEdge(clew, out.has_peak ? peak : head);
  Edge top;
  if (out.has_peak) top = makeEdge(head, peak);
  const double sp = out.boundary_spacing_m;
  const double mesh_area = meshArea(mesh);
  const double density = sample_density_per_m2 > 0
                             ? sample_density_per_m2
                             : static_cast<double>(mesh.vertices.size()) / std::max(1e-12, mesh_area);
  const double reach = std::max(0.05 * total, 10.0 * sp);
  // An edge beside scan lines lies anywhere up to a line spacing beyond the last
  // line (uniform: σ = spacing / √12), whatever its fit's own scatter.
  auto reported = [](const Edge& e) { return std::hypot(e.section_sigma, e.line_spacing / std::sqrt(12.0)); };
  out.luff_sigma_m = reported(luff);
  out.leech_sigma_m = reported(leech);
  out.foot_sigma_m = reported(foot);
  if (out.has_peak) out.top_sigma_m = reported(top);
  // How well a corner is placed: 1σ along and across its bisector, and the half
  // angle between its edges (how its shifts move the edges' lengths and lines).
  struct CornerSpread {
    double along_m = 0, across_m = 0, half_rad = 0;
    double position() const { return std::hypot(along_m, across_m); }
    // σ across one of its edges: the bisector leaves each edge at the half angle.
    double acrossEdge() const { return std::hypot(along_m * std::sin(half_rad), across_m * std::cos(half_rad)); }
  };
  auto corner = [&](const Edge& a, bool a_start, const Edge& b, bool b_start, CornerSpread& spread) {
    const Meeting m = meetEdges(a, a_start, b, b_start, sp, samples);
    const double chord_angle =
        std::acos(std::clamp(edgeChord(a, a_start, m.point, sp).dot(edgeChord(b, b_start, m.point, sp)), -1.0, 1.0));
    const PlacedCorner c = placeCorner(m, mesh, tree, loose_points, density, reach, sp, chord_angle);
    // Moving the two edges sideways by ε_a and ε_b moves their crossing across the
    // bisector by (ε_a − ε_b) / (2 cos(angle / 2)).
    const double across = std::hypot(m.side_a_m, m.side_b_m) / (2.0 * std::cos(std::min(0.5 * m.angle_rad, 1.4)));
    const Vec3 shift = footprint ? footprintShift(p, *scanner, c.point, a, a_start, b, b_start, sp) : Vec3(Vec3::Zero());
    spread = {std::hypot(c.sigma_m, kFootprintUncertainty * shift.norm(), m.model_along_m),
              std::hypot(across, m.model_across_m), 0.5 * m.angle_rad};
    return ontoSurface(Vec3(c.point + shift), mesh, tree, sp);
  };
  CornerSpread at_tack, at_clew, at_head, at_peak;
  out.tack = corner(luff, true, foot, true, at_tack);
  out.clew = corner(foot, false, leech, true, at_clew);
  if (out.has_peak) {
    out.head = corner(luff, false, top, true, at_head);
    out.peak = corner(leech, false, top, false, at_peak);
  } else {
    out.head = corner(luff, false, leech, false, at_head);
  }
  out.tack_sigma_m = at_tack.along_m;
  out.clew_sigma_m = at_clew.along_m;
  out.head_sigma_m = at_head.along_m;
  out.peak_sigma_m = at_peak.along_m;
  SailOutline::Uncertainty& u = out.uncertainty;
  u.tack_m = at_tack.position();
  u.clew_m = at_clew.position();
  u.head_m = at_head.position();
  u.peak_m = at_peak.position();
  for (const auto& [name, e] : {std::pair<const char*, const Edge*>{"luff", &luff}, {"leech", &leech}, {"foot", &foot},
                                {"top edge", &top}})
    if (e->line_spacing > 0)
      out.warnings.push_back(
          std::string(name) + ": its samples lie on scan lines running beside it, about " +
          formatFixed(100 * e->line_spacing, 1) + " cm apart (a cloud without its scan angles?); " +
          (e->along_lines ? "the edge runs through the lines' ends and between them is known to a line spacing"
                          : "the edge is placed by the last line, up to a line spacing inside it") +
          ", and the corners at its ends may lie further off than that");
  out.luff = edgePolyline(luff, out.tack, out.head, sp);
  out.foot = edgePolyline(foot, out.tack, out.clew, sp);
  out.leech = edgePolyline(leech, out.clew, out.has_peak ? out.peak : out.head, sp);
  if (out.has_peak) out.top = edgePolyline(top, out.head, out.peak, sp);
  if (footprint) {
    // Between the corners (moved out already) each point of an edge goes out by the
    // footprint's reach there; the edge's σ takes the reach's own uncertainty.
    auto moveOut = [&](std::vector<Vec3>& line, double& sigma) {
      if (line.size() < 3) return 0.0;
      std::vector<Vec3> moved = line;
      std::vector<uint32_t> idx;
      std::vector<double> d2;
      double sum = 0;
      for (size_t i = 1; i + 1 < line.size(); ++i) {
        const Vec3 t = (line[i + 1] - line[i - 1]).normalized();
        const Vec3 in = acrossAt(line[i], line[i], t, samples, idx, d2).in;
        const double s = footprintReach(p, *scanner, line[i], t.cross(in).normalized(), -in);
        moved[i] = line[i] - s * in;
        sum += s;
      }
      line = std::move(moved);
      const double mean = sum / static_cast<double>(line.size() - 2);
      sigma = std::hypot(sigma, kFootprintUncertainty * mean);
      return mean;
    };
    const double at_luff = moveOut(out.luff, out.luff_sigma_m);
    moveOut(out.foot, out.foot_sigma_m);
    const double at_leech = moveOut(out.leech, out.leech_sigma_m);
    out.footprint_reach_m = std::max(at_luff, at_leech);
    if (out.has_peak) moveOut(out.top, out.top_sigma_m);
  }
  out.luff_length_m = polylineLength(out.luff);
  out.leech_length_m = polylineLength(out.leech);
  out.foot_length_m = polylineLength(out.foot);
  out.top_length_m = polylineLength(out.top);
  // The sail beyond the mesh: between each edge's sampled boundary and its outline,
  // corners included (a wide corner's boundary rounds off over half a metre, which
  // the edges' recess times their lengths left out: clean gennakers' areas came out
  // 0.03-0.06 m² short).
  // Seen from `up` each sampled edge runs anticlockwise (as the loop does about its
  // normal) when it follows the loop's order, clockwise when it runs against it.
  auto strip = [&](size_t from, size_t to, const std::vector<Vec3>& outline) {
    const std::vector<Vec3> sampled = edge(from, to);
    const bool with_loop = sampled.size() > 1 && sampled[1] == pts[(from + 1) % n];
    return ribbonArea(sampled, outline, with_loop ? loop_normal : Vec3(-loop_normal));
  };
  double area_outside = strip(tack, head, out.luff) + strip(tack, clew, out.foot) +
                        strip(clew, out.has_peak ? peak : head, out.leech);
  if (out.has_peak) area_outside += strip(head, peak, out.top);
  out.area_m2 = mesh_area + area_outside;
  // A corner's shift along its bisector moves each of its edges' ends along the
  // edge by cos(half angle) of it; an edge's shift across moves the area by its
  // length (the edges' σ are mostly their common offset, so taken whole).
  auto lengthSigma = [](const CornerSpread& from, const CornerSpread& to) {
    return std::hypot(from.along_m * std::cos(from.half_rad), to.along_m * std::cos(to.half_rad));
  };
  u.luff_length_m = lengthSigma(at_tack, at_head);
  u.foot_length_m = lengthSigma(at_tack, at_clew);
  u.leech_length_m = lengthSigma(at_clew, out.has_peak ? at_peak : at_head);
  if (out.has_peak) u.top_length_m = lengthSigma(at_head, at_peak);
  u.luff_line_m = 0.5 * std::hypot(at_tack.acrossEdge(), at_head.acrossEdge());
  u.area_m2 = std::sqrt(std::pow(out.luff_sigma_m * out.luff_length_m, 2) + std::pow(out.leech_sigma_m * out.leech_length_m, 2) +
                        std::pow(out.foot_sigma_m * out.foot_length_m, 2) + std::pow(out.top_sigma_m * out.top_length_m, 2));

  if (!p.design_lengths_m.empty()) {
    const char* names[3] = {"luff", "leech", "foot"};
    const double measured[3] = {out.luff_length_m, out.leech_length_m, out.foot_length_m};
    const double sigma[3] = {u.luff_length_m, u.leech_length_m, u.foot_length_m};
    for (int i = 0; i < 3; ++i) {
      const double design = p.design_lengths_m[static_cast<size_t>(i)];
      if (!(design > 0)) continue;
      const double off = std::abs(measured[i] - design) / design;
      if (off > p.design_tolerance)
        throw AnalysisError(std::string("[extractOutline] ") + names[i] + " length " + formatFixed(measured[i]) + " m is " +
                            formatFixed(100 * off, 1) + " % off the design " + formatFixed(design) + " m (limit " +
                            formatFixed(100 * p.design_tolerance, 0) + " %): corners or segmentation are wrong");
      if (off > p.design_warning && std::abs(measured[i] - design) > 3.0 * sigma[i])
        out.warnings.push_back(std::string(names[i]) + " length " + formatFixed(measured[i]) + " m is " +
                               formatFixed(100 * off, 1) + " % " + (measured[i] < design ? "shorter" : "longer") +
                               " than the design's " + formatFixed(design) + " m: " +
                               (measured[i] < design ? "the scan may not reach a corner, or the beam's footprint trims "
                                                       "a narrow head; "
                                                     : "the sail cluster may hold more than the sail; ") +
                               "the sections sit at fractions of the edges as measured");
    }
  }
  return out;
}

}  // namespace sailshape
