// The edge model: each sail edge between two corners, a smooth curve through its
// boundary points moved out to where the surface really ends (the boundary samples
// lie inside it), with its uncertainty.
#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {

EdgeCurve fitEdgeCurve(const std::vector<Vec3>& pts, const std::vector<double>& s, int degree) {
  Eigen::MatrixXd xyz(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) xyz.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
  return EdgeCurve{fitPolynomialOverRange(s, xyz, degree)};
}

double recessFromLeast(double least, double D, double n) {
  const double q = 1.0 / (n + 1.0);
  return (q * D - least) / (1.0 - q);
}

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

// The lower envelope of samples (s, o) (o positive inwards): the polynomial of the
// given degree that lies beyond (o below) the outermost sample of every stretch
// `window` long and is as far in as that allows on the whole (a linear programme:
// maximise Σ p(s_w) subject to p(s_w) ≤ least_w, solved exactly by CGAL). Where scan
// lines cross an edge, each line ends on it, so the envelope touches the line ends
// and is the edge; a fit through the outermost samples would follow the staircase
// the last line leaves between crossings. nullopt when the programme has no optimum.
// `along_offset` ascending in arc position, as for frontierRecess.
std::optional<Polynomial> lowerEnvelope(const AlongOffset& along_offset, double window, int degree) {
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
  p.centre = 0.5 * (s.front() + s.back());
  p.scale = std::max(1e-9, 0.5 * (s.back() - s.front()));
  CGAL::Quadratic_program<double> lp(CGAL::SMALLER, false, 0, false, 0);
  std::vector<double> objective(static_cast<size_t>(degree) + 1, 0.0);
  for (size_t w = 0; w < s.size(); ++w) {
    const double u = p.variable(s[w]);
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

// The direction from `corner` to the point a tenth of edge e's length along it
// (from its start when at_start, else from its end): how the sail's samples open
// from a corner, which the corner curves' own tangents where they meet, extrapolated
// past the samples, may not show (they can close in to parallel).
Vec3 edgeChord(const Edge& e, bool at_start, const Vec3& corner, double spacing) {
  const double l = std::clamp(0.1 * e.length, std::min(e.exclude + spacing, 0.5 * e.length), 0.5 * e.length);
  return Vec3(e.curve.at(at_start ? l : e.length - l) - corner).normalized();
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

namespace {

struct Frontier {
  double recess = 0;                  // m
  size_t windows = 0;
  std::vector<double> centre, local;  // each window's mid arc position and recess estimate, m
  double median = 0;                  // of `local`, m
  double mean_gap = 0;                // m
};

// The recess δ from the outermost samples: the samples' offsets o from the found
// edge (positive inwards, o <= D) in windows `window` long along it; in a window
// of n, uniform on [−δ, D], the least lies above −δ by a gap near exponential
// with mean (D + δ)/(n + 1). The median over the windows (a stray sample beyond
// the edge spoils only its own window) exceeds the mean of such gaps' estimates
// by (1 − ln 2) of a mean gap; that is taken off. `along_offset` ascending in arc
// position.
Frontier frontierRecess(const AlongOffset& along_offset, double D, double window) {
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

// How the samples beside an edge lie across it. Sorted by offset within a window,
// consecutive samples leave gaps G; the expected distance from an edge placed at
// random among them to the first sample is E[G²] / (2 E[G]) (the residual life of
// a stationary point process). A uniform scatter leaves exponential gaps, and that
// distance equals the mean gap (a ratio of 1). Scan lines running beside the edge
// (a 2D scanner on a turntable, its cloud given without the scan angles) put many
// samples at one offset and leave a line spacing s between lines: the residual
// distance is s / 2, many mean gaps.
struct GapShape {
  double mean_gap = 0;  // m
  double residual = 0;  // E[G²] / (2 E[G]), m
  double gaps = 0;      // how many gaps they were read from
  double ratio() const { return mean_gap > 0 ? residual / mean_gap : 0; }
};

// `along_offset` ascending in arc position, as for frontierRecess.
GapShape gapShape(const AlongOffset& along_offset, double window) {
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
// it (30/√gaps bounds it over uniform scatters of every sail type and density the
// bench sweeps, bench/independent-sails).
bool onScanLines(const GapShape& g) { return g.gaps > 0 && g.ratio() > 1.5 + 30.0 / std::sqrt(g.gaps); }

// The points of e its curve is fitted through: those more than e.exclude from
// either corner (the boundary rounds the corners off), or every point of a very
// short edge (e.exclude then 0). Sets e.length and e.exclude.
std::vector<size_t> innerPoints(Edge& e, double spacing) {
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
  return inner;
}

// e.curve through the inner points as they lie now.
void refitCurve(Edge& e, const std::vector<size_t>& inner, int degree) {
  std::vector<Vec3> pts;
  std::vector<double> s;
  for (size_t i : inner) {
    pts.push_back(e.points[i]);
    s.push_back(e.s[i]);
  }
  e.curve = fitEdgeCurve(pts, s, degree);
}

// The direction into the surface at each of e's points: surface normal × the
// curve's tangent, towards the mesh.
std::vector<Vec3> inwardDirections(const Edge& e, const Samples& smp) {
  std::vector<uint32_t> idx;
  std::vector<double> d2;
  std::vector<Vec3> inward(e.points.size());
  for (size_t i = 0; i < e.points.size(); ++i) {
    const double si = std::clamp(e.s[i], e.exclude, e.length - e.exclude);
    inward[i] = acrossAt(e.points[i], e.curve.at(si), e.curve.tangent(si), smp, idx, d2).in;
  }
  return inward;
}

// The strip beside an edge, `depth` deep inside it, whose samples place the edge.
struct EdgeStrip {
  const Edge& e;
  const Samples& smp;
  const std::vector<Vec3>& inward;  // at each of e's points
  double depth = 0;                 // m
  double spacing = 0;               // boundary spacing, m

  // The samples in the strip, as (arc position, offset o) with lowest <= o <= depth:
  // round the points `at` of the edge, each within a spacing along it of `centre(i)`
  // (tangent `tangent(i)`), offsets along inward[i]. The disc searched must hold
  // the whole window |along| <= spacing, 0 <= o <= depth: a disc of radius `depth`
  // alone cuts its far corners, thins the samples near o = depth and so overstates
  // the recess (by about 0.08 × spacing).
  template <typename Centre, typename Tangent>
  AlongOffset samples(const std::vector<size_t>& at, Centre centre, Tangent tangent, double lowest) const {
    AlongOffset out;
    std::vector<uint32_t> idx;
    std::vector<double> d2;
    std::vector<char> seen(smp.mesh.vertices.size(), 0);
    for (size_t i : at) {
      const Vec3 c = centre(i), t = tangent(i);
      smp.tree.withinRadius(c, std::hypot(depth, spacing), idx, d2);
      for (uint32_t v : idx) {
        if (seen[v]) continue;
        const Vec3 d = smp.mesh.vertices[v] - c;
        if (std::abs(d.dot(t)) > spacing) continue;  // belongs to a neighbouring point
        seen[v] = 1;
        const double o = d.dot(inward[i]);
        if (o <= depth && o >= lowest) out.emplace_back(e.s[i] + d.dot(t), o);
      }
    }
    return out;
  }
  // The same measured from the edge's fitted curve as it is now.
  AlongOffset besideCurve(const std::vector<size_t>& at, double lowest) const {
    return samples(
        at, [&](size_t i) { return e.curve.at(e.s[i]); }, [&](size_t i) { return e.curve.tangent(e.s[i]); }, lowest);
  }
};

// Moves e's points out by the recess the frontier windows give along the edge, and
// fits the curve again; returns the recess' σ. The recess along the edge is a
// polynomial of the curve's degree (at most a third as many coefficients as
// windows) through the windows' estimates, each held within 4 mean gaps of their
// median (a stray beyond the edge). It takes out the curve's own wiggles, which a
// least-squares fit through boundary samples scattered by one gap each leaves.
double moveOntoFrontier(Edge& e, const std::vector<size_t>& inner, int degree, const Frontier& frontier,
                        const std::vector<Vec3>& inward, double strip) {
  e.recess = std::clamp(frontier.recess, 0.0, strip);
  const size_t m = frontier.local.size();
  const int deg = std::min(degree, static_cast<int>(m / 3) - 1);
  Eigen::MatrixXd held(static_cast<Eigen::Index>(m), 1);
  for (size_t j = 0; j < m; ++j)
    held(static_cast<Eigen::Index>(j), 0) = std::clamp(
        frontier.local[j], frontier.median - 4.0 * frontier.mean_gap, frontier.median + 4.0 * frontier.mean_gap);
  const Polynomial recess = fitPolynomialOverRange(frontier.centre, held, deg);
  const double first = frontier.centre.front(), last = frontier.centre.back();
  for (size_t i = 0; i < e.points.size(); ++i) {
    const double d = recess.at(std::clamp(e.s[i], first, last))[0];  // held at the end windows' value beyond them
    e.points[i] -= std::clamp(d, 0.0, strip) * inward[i];
  }
  refitCurve(e, inner, degree);
  return frontier.mean_gap * std::sqrt(static_cast<double>(deg + 1) / static_cast<double>(m));
}

// The windows' estimates spread as their gaps do, (D + δ)/(n + 1) each, which a fit
// through them averages down only as the root of their count. All the samples
// beside the edge at once place it sharper: the polynomial lying beyond every one
// of them and as far in as that allows (their lower envelope, as on scan lines)
// misses the true edge by the band that holds, on average, as many samples as it
// has coefficients, q + 1 over the strip's density ρ and the edge's length L:
// (q + 1)/(ρ L) inside it, with about as much spread (checked over uniform
// scatters in simulation for degrees 0-5 and edges 3-12.5 m long). It is moved out
// by that.
//
// The envelope rests on the outermost samples and nothing else, so noise across the
// edge (range noise in a scan that meets the sail obliquely) pulls it out by the
// noise's extremes, where the windows' estimates move by its mean: it is kept only
// while it lies, over most of the edge (its median offset), within the windows' own
// σ beyond their curve. Noise pulls it out all along; a stretch of the edge where
// the outermost samples fell unluckily deep pulls the windows' curve in there only,
// which is no reason to leave the envelope (the mean would be). The corner curves
// keep the windows' points: near a corner the envelope rests on few samples.
//
// When kept, e.curve runs on the envelope (e.points stay the windows'), sigma_recess
// becomes the envelope's, and the result is true.
bool ontoLowerEnvelope(Edge& e, const EdgeStrip& strip, const std::vector<size_t>& every_other,
                       const std::vector<size_t>& inner, int degree, double& sigma_recess) {
  AlongOffset beside = strip.besideCurve(every_other, -strip.depth);
  std::sort(beside.begin(), beside.end());
  const std::optional<Polynomial> envelope = lowerEnvelope(beside, strip.spacing, degree);
  if (!envelope) return false;
  const double lo = envelope->centre - envelope->scale, hi = envelope->centre + envelope->scale;
  auto offset = [&](double at) { return envelope->at(std::clamp(at, lo, hi))[0]; };
  double offset_sum = 0;
  for (const auto& [along, o] : beside) offset_sum += offset(along);
  const double width = strip.depth - offset_sum / static_cast<double>(std::max<size_t>(1, beside.size()));
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
  if (!(profile[kSteps / 2] >= -sigma_recess)) return false;
  const std::vector<Vec3> windows_points = e.points;
  for (size_t i = 0; i < e.points.size(); ++i)
    e.points[i] += std::clamp(offset(e.s[i]) - gap, -strip.depth, strip.depth) * strip.inward[i];
  refitCurve(e, inner, degree);
  e.points = windows_points;
  sigma_recess = std::hypot(gap, mean_offset);
  return true;
}

// e.scatter, e.sigma and e.section_sigma: a least-squares curve with degree + 1
// coefficients through N points with scatter σ_res is known to σ_res·√((degree + 1)/N),
// and the recess that moved it out to sigma_recess.
void setEdgeSigma(Edge& e, const std::vector<size_t>& inner, int degree, double sigma_recess, bool on_envelope) {
  double res2 = 0;
  for (size_t i : inner) res2 += (e.points[i] - e.curve.at(e.s[i])).squaredNorm();
  const double sigma_res = std::sqrt(res2 / static_cast<double>(std::max<size_t>(1, inner.size() - 1)));
  e.scatter = sigma_res;
  const double sigma_curve = sigma_res * std::sqrt(static_cast<double>(degree + 1) / static_cast<double>(inner.size()));
  e.sigma = std::hypot(sigma_curve, sigma_recess);
  e.section_sigma = on_envelope ? sigma_recess : e.sigma;
  e.on_envelope = on_envelope;
}

// An edge beside scan lines: the edge through the lines' ends, the samples' lower
// envelope along the whole edge, up to the corners (the fitted curve's straight
// continuation is the reference beyond its range; the other edge's samples near a
// corner lie inside and do not count). Where the boundary cuts into the sail (a
// line left out of the mesh), the 24 vertices round it lie on both sides and the
// inward direction can turn over: those stretches are left out. The curve between
// the corners, which the sections end on, then runs along the envelope; the corners
// keep the scatter's placement of the points near them (placed from the envelope's
// ends, which it holds beyond the samples, they moved as often away from the
// corner as towards it).
void alongScanLines(Edge& e, const EdgeStrip& strip, const std::vector<size_t>& inner, int degree) {
  const std::vector<Vec3>& inward = strip.inward;
  auto reference = [&](double s_at) {
    const double sc = std::clamp(s_at, e.exclude, e.length - e.exclude);
    return Vec3(e.curve.at(sc) + (s_at - sc) * e.curve.tangent(sc));
  };
  Vec3 inward_mean = Vec3::Zero();
  for (size_t i : inner) inward_mean += inward[i];
  std::vector<size_t> facing;
  for (size_t i = 0; i < e.points.size(); i += 2)
    if (inward[i].dot(inward_mean) > 0) facing.push_back(i);
  auto reference_tangent = [&](size_t i) { return e.curve.tangent(std::clamp(e.s[i], e.exclude, e.length - e.exclude)); };
  // Two line spacings beyond the curve is a stray, not a line's end.
  AlongOffset beside = strip.samples(
      facing, [&](size_t i) { return reference(e.s[i]); }, reference_tangent, -2.0 * e.line_spacing);
  std::sort(beside.begin(), beside.end());
  const std::optional<Polynomial> envelope = lowerEnvelope(beside, strip.spacing, degree);
  // It lies within a line spacing and a half beyond the curve through the boundary
  // and no more than half a spacing inside it; further off, the boundary is not the
  // lines' (it cut into the sail or left it) and the edge is placed as a scatter's.
  if (!envelope) return;
  const double first = envelope->centre - envelope->scale, last = envelope->centre + envelope->scale;
  for (size_t i : inner) {
    const double p = envelope->at(std::clamp(e.s[i], first, last))[0];
    if (!(p >= -1.5 * e.line_spacing && p <= 0.5 * e.line_spacing)) return;
  }
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

}  // namespace

// A sampled surface's boundary lies inside the true edge: the outermost samples
// sit some distance in. Sample offsets from the true edge are uniform on
// [0, ∞), so within the strip o ≤ D of the found edge (offset o from it,
// positive inwards) they are uniform on [−δ, D]. The recess δ comes from the
// outermost samples of each stretch of the edge (frontierRecess), or, on an edge
// too short for that, from δ = D − 2·mean(o); the edge's points are moved out by
// it and the curve is fitted again.
void fitEdge(Edge& e, const Samples& smp, double spacing) {
  const std::vector<size_t> inner = innerPoints(e, spacing);
  const int degree = static_cast<int>(std::clamp<size_t>(inner.size() / 8, 1, 5));
  refitCurve(e, inner, degree);
  const std::vector<Vec3> inward = inwardDirections(e, smp);
  const EdgeStrip strip{e, smp, inward, kFrontierStripSpacings * spacing, spacing};
  std::vector<size_t> every_other;
  for (size_t k = 0; k < inner.size(); k += 2) every_other.push_back(inner[k]);
  AlongOffset along_offset = strip.besideCurve(every_other, -std::numeric_limits<double>::infinity());
  double sum = 0;
  for (const auto& [along, o] : along_offset) sum += o;
  const size_t count = along_offset.size();
  // δ's σ: offsets spread over about the strip width, uniform.
  double sigma_recess = strip.depth / std::sqrt(3.0);
  if (count >= 30) {
    e.recess = std::clamp(strip.depth - 2.0 * sum / static_cast<double>(count), 0.0, strip.depth);
    sigma_recess = 2.0 * strip.depth / std::sqrt(12.0 * static_cast<double>(count));
  }
  // The mean of the offsets uses every sample in the strip but spreads with the
  // strip's width. The outermost sample of each stretch of the edge lies inside it
  // by a gap that spreads only as much as it is long: estimates from those are
  // several times sharper. They also hold after smoothing, which pulls a noisy
  // scan's outermost samples in less than the samples behind them, and so the mean
  // short of the edge.
  std::sort(along_offset.begin(), along_offset.end());  // for the windows along the edge
  const double window = kFrontierWindowSpacings * spacing;
  const Frontier frontier = count >= 30 ? frontierRecess(along_offset, strip.depth, window) : Frontier{};
  // The frontier model is a scatter's; on scan lines it places the edge by the last
  // line, up to a line spacing inside (extractOutline says so and widens σ).
  if (count >= 30) {
    const GapShape gaps = gapShape(along_offset, window);
    if (onScanLines(gaps)) e.line_spacing = 2.0 * gaps.residual;
  }
  bool on_envelope = false;  // the curve moved onto the samples' lower envelope
  if (frontier.windows >= 6) {
    sigma_recess = moveOntoFrontier(e, inner, degree, frontier, inward, strip.depth);
    if (e.line_spacing == 0) on_envelope = ontoLowerEnvelope(e, strip, every_other, inner, degree, sigma_recess);
  } else if (e.recess > 0) {
    for (size_t i = 0; i < e.points.size(); ++i) e.points[i] -= e.recess * inward[i];
    refitCurve(e, inner, degree);
  }
  setEdgeSigma(e, inner, degree, sigma_recess, on_envelope);
  if (e.line_spacing > 0) alongScanLines(e, strip, inner, degree);
}

}  // namespace sailshape::outline_internal
