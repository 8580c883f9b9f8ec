// Where two edges meet: each edge's corner curve moved onto the samples beside it,
// their crossing, bounded by how far the samples reach (placeCorner), put onto the
// surface and moved out by the beam's footprint, with its uncertainty.
#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/core/units.hpp"
#include "analysis/outline/outline_internal.hpp"
#include "analysis/segmentation/plane_detection.hpp"

namespace sailshape::outline_internal {
namespace {

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

// A narrow corner's curves (under 60°: a head) move onto the samples' frontier
// (ontoFrontier), and then, where both whole edges rest on their samples' lower
// envelope (a clean scatter: fitEdge keeps it only while noise across the edge does
// not pull it out), onto the lower envelope beside each frontier curve
// (ontoEnvelope). The windows' estimates err one way far more than the other (a
// window whose outermost sample fell unluckily deep lies several gaps inside), and
// near the head the windows are short and few, so that a frontier curve alone can
// put the head low by several centimetres.
void narrowCornerCurves(const Edge& a, const Edge& b, double spacing, const Samples& smp, CornerCurve& ca,
                        CornerCurve& cb) {
  CornerCurve fa = ontoFrontier(ca, cb, smp, spacing, false), fb = ontoFrontier(cb, ca, smp, spacing, false);
  // Once more from the frontier curves, over the corner curves' reach. A window's
  // outermost sample is measured from the curve, and where that curve strays from
  // the edge within the window (the corner curve through boundary vertices, with
  // windows most of a metre long in a sparse scan) the least offset is the edge's
  // furthest excursion there, not its place, and a cubic follows it. Measured from
  // the frontier curve, the edge runs nearly straight in each window.
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

// A wide corner's curves (a tack, a clew, a square head) shorten where an edge
// bends; then, if neither edge turns more than kFollowedTurnRad over a frontier
// window, both move onto the frontier too, with windows from the corner itself over
// the unshortened reach: the boundary rounds off a wide corner over half a metre and
// more, and lies centimetres inside it there. A foot leaving the tack at its entry
// angle turns more than that over a window, more than the windows' curve follows
// (on the frontier it would put the tack centimetres off): such a corner keeps its
// shortened quadratics, moved onto their samples' lower envelope (ontoEnvelope).
// The window is the one ontoFrontier would use on that edge (shorter on a short
// edge: a square top's cambered top edge, or most edges of a sparse scan, turn less
// over their own windows than over 5 spacings, and are followed).
void wideCornerCurves(const Edge& a, bool a_start, const Edge& b, bool b_start, double spacing, const Samples& smp,
                      CornerCurve& ca, CornerCurve& cb) {
  // Feet turn about 0.05 rad over a window at the clew, luffs and leeches less;
  // a foot leaving the tack at its entry angle, 0.1 rad and more.
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
}

// The closest pair of points of the two edges' corner curves (quadratics in the
// distance from the corner, extrapolated back to it), once each curve has been
// moved onto the samples beside it as the corner's width allows (narrowCornerCurves,
// wideCornerCurves).
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
  if (wide) wideCornerCurves(a, a_start, b, b_start, spacing, smp, ca, cb);
  else narrowCornerCurves(a, b, spacing, smp, ca, cb);
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
  // the outermost samples bound the corner anyway (placeCorner), and the added term
  // would overstate its σ: it counts at wide corners only.
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
  double radius = 1;  // (u, v) are in units of it
  QuadraticHeightField surface;
  double rms_m = 0;   // the vertices' scatter about it
  // Signed height of q over the field, along `normal`.
  double offset(const Vec3& q) const {
    const Vec3 d = q - origin;
    return d.dot(normal) - surface.height(d.dot(eu) / radius, d.dot(ev) / radius);
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
  for (uint32_t v : idx) {
    const Vec3 d = mesh.vertices[v] - c;
    f.surface.add(d.dot(f.eu) / radius, d.dot(f.ev) / radius, d.dot(f.normal));
  }
  if (!f.surface.solve()) return std::nullopt;
  f.rms_m = std::sqrt(f.surface.residualSumOfSquares() / std::max<double>(1.0, static_cast<double>(idx.size()) - 6));
  return f;
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
  // be found as a corner). The outermost sample along the bisector, within reach
  // of it sideways, bounds it then.
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
  // The wedge opens at least as the edges' chords from the crossing do: corner
  // curves can meet nearly parallel at a narrow head, which would leave the tip's
  // gap unbounded and the head far beyond its samples. (Edges parallel to the last
  // bit still leave a wedge: the half angle is floored as meetEdges floors it, so
  // that λ > 0.)
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
// tack at the entry angle and curves away), which can leave the crossing
// centimetres off the surface. The corner lies on the surface: it moves onto the
// height field along its normal.
Vec3 ontoSurface(const Vec3& c, const Mesh& mesh, const PointGrid& tree, double spacing) {
  const std::optional<HeightField> f = heightFieldAround(c, mesh, tree, spacing);
  return f ? Vec3(c + f->surface.coeffs[0] * f->normal) : c;
}

}  // namespace

Vec3 placeCornerBetween(const Edge& a, bool a_start, const Edge& b, bool b_start, const CornerContext& ctx,
                        CornerSpread& spread) {
  const double sp = ctx.spacing_m;
  const Mesh& mesh = ctx.samples.mesh;
  const PointGrid& tree = ctx.samples.tree;
  const Meeting m = meetEdges(a, a_start, b, b_start, sp, ctx.samples);
  const double chord_angle =
      std::acos(std::clamp(edgeChord(a, a_start, m.point, sp).dot(edgeChord(b, b_start, m.point, sp)), -1.0, 1.0));
  const PlacedCorner c = placeCorner(m, mesh, tree, ctx.loose_points, ctx.density_per_m2, ctx.reach_m, sp, chord_angle);
  // Moving the two edges sideways by ε_a and ε_b moves their crossing across the
  // bisector by (ε_a − ε_b) / (2 cos(angle / 2)).
  const double across = std::hypot(m.side_a_m, m.side_b_m) / (2.0 * std::cos(std::min(0.5 * m.angle_rad, 1.4)));
  const Vec3 shift = ctx.footprint_scanner
                         ? footprintShift(ctx.params, *ctx.footprint_scanner, c.point, a, a_start, b, b_start, sp)
                         : Vec3(Vec3::Zero());
  spread = {std::hypot(c.sigma_m, kFootprintUncertainty * shift.norm(), m.model_along_m),
            std::hypot(across, m.model_across_m), 0.5 * m.angle_rad};
  return ontoSurface(Vec3(c.point + shift), mesh, tree, sp);
}

}  // namespace sailshape::outline_internal
