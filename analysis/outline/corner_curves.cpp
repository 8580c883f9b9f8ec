// Each edge's curve near a corner: a quadratic through its last boundary points,
// then moved onto the outermost samples beside it (ontoFrontier) or their lower
// envelope (ontoEnvelope), which place the edge there more sharply.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "analysis/outline/outline_internal.hpp"

namespace sailshape::outline_internal {
namespace {

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

}  // namespace

// The curve reaches max(60 boundary spacings, 5 % of the edge) from the corner.
// With `shorten_if_bent` the reach shrinks by steps of 1.25 (to no less than 20
// spacings) while the points scatter about the quadratic more than they scatter
// about the whole edge's curve and a shorter reach lowers that scatter: the edge
// bends more than a quadratic follows there, as a gennaker's foot does leaving the
// tack at its entry angle and curving away. Near a narrow head the scatter rises for another reason (the sail is
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
    // Down to 20 spacings, where the fit still has 16 points and more: a quadratic,
    // and short enough to follow a foot's turn away from the tack in a sparse scan
    // (boundary vertices many centimetres apart). A reach beyond the edge's end takes
    // the same points and is passed over: its equal fit would end the search on an
    // edge shorter than the first reach, with a quadratic over the whole edge.
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

// A corner curve fitted through the boundary vertices carries their scatter (a
// gap each), and fitted over 60 boundary spacings it cannot follow how an edge
// bends on the last few metres to a narrow head. Extrapolated to the corner,
// either moves the edges' crossing by several times as much along the bisector.
//
// The outermost of the many samples beside the edge place it far more sharply.
// In each window along the curve, the samples' offsets o from it (positive
// inwards) are uniform on [−δ, D], and the least of n lies a gap (D + δ)/(n + 1)
// beyond −δ on average (as frontierRecess): δ is known to about that gap, a few
// millimetres. Near a corner D is cut to half the sail's width, where the other
// edge's samples begin, in each eighth of the window along it (D then its mean
// over them: near the edge, where the least lies, the strip runs the window's
// whole length). Cut to the width at the window's narrowest instead, a window
// reaching into a wide corner (through which the other edge passes) would hold
// next to nothing and be left out, and the edge be extrapolated over a window and
// a half. The frontier points so found take a quadratic or a cubic over the first
// m windows; each candidate is known at the corner to s·√(x₀ᵀ(AᵀA)⁻¹x₀) (x₀ the
// corner's powers, s the points' scatter: the least-squares prediction there). Of
// the candidates that fit their points as closely as those scatter, the one known
// best at the corner wins; if none does, the one whose misfit costs least. The
// points' own scatter comes from the second differences of their offsets, in which
// a smooth bend cancels and noise adds 6σ² (median-based, so a stray window counts
// little). With `from_corner` the windows start at the corner itself, not where
// the curve's own fit began (the samples reach closer to a wide corner than its
// boundary).
//
// An edge too short for 8 windows of 5 spacings takes 8 shorter ones, down to a
// spacing each (a square top's top edge, a metre or two long, would have too few
// windows and keep a corner curve through a dozen boundary vertices of a cambered
// section, well off the surface at its ends). On such an edge each frontier point
// is also taken on the surface under the curve (the mean plane of the 24 vertices
// nearest it), not on the curve: the offsets o are measured across the surface, so
// a curve that leaves it in depth would carry that into every point. On a longer
// edge the curve follows the surface to a millimetre, and those planes would only
// add their own scatter (enough along a mainsail's foot to fail the residual test).
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
      for (int e = 0; e <= degree; ++e) A(static_cast<Eigen::Index>(j), e) = std::pow((ds[j] - f.centre) / f.scale, e);
    }
    for (int e = 0; e <= degree; ++e) x0[e] = std::pow(-f.centre / f.scale, e);
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
  // choice alone moves the corner (without it, corners lay well beyond their σ).
  if (best->fits && fitting_corners.size() > 1) {
    const Vec3 chosen = best->curve.curve.at(0);
    double ss = 0;
    for (const Vec3& q : fitting_corners) ss += std::pow((q - chosen).dot(first_in), 2);
    best->curve.model_sigma = std::sqrt(ss / static_cast<double>(fitting_corners.size() - 1));
  }
  return best->curve;
}

// A wide corner whose edge bends more than ontoFrontier's windows follow (a
// gennaker's foot leaving the tack) keeps its shortened quadratic through the
// boundary vertices, which carry a gap's scatter each and follow a notch where few
// samples fell near the edge. All the samples beside the curve, from the corner to
// its reach, place it sharper: their lower envelope, a quadratic relative to the
// curve lying beyond every one of them, as fitEdge's for a whole edge, moved out by
// the band (q + 1)/(ρ L) it leaves on average. A notch only loosens the constraints
// where it lies. Extrapolated to the corner a quadratic spreads several times its
// interior error either way; the envelope's value there spreads less than the
// windows' (about 0.6 of it over uniform scatters in simulation). The curve's σ at
// the corner stays its least-squares one, a bound on this. Below 12 windows of a
// spacing, or when the programme has no optimum, the curve stays as it was.
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
  const double lo = envelope->centre - envelope->scale, hi = envelope->centre + envelope->scale;
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

}  // namespace sailshape::outline_internal
