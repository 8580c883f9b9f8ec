#pragma once
// What the outline's files share (boundary.cpp, corners.cpp, edges.cpp,
// corner_curves.cpp, corner_placement.cpp, beam_footprint.cpp, sail_outline.cpp).
// Internal to analysis/outline: nothing outside this folder includes it.
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "analysis/core/fit.hpp"
#include "analysis/outline/sail_outline.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape::outline_internal {

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

// ---- boundary.cpp: the mesh's outer boundary loop ----

// The longest closed loop of boundary edges, as vertex indices.
std::vector<uint32_t> outerBoundaryLoop(const Mesh& mesh);

// The outer boundary as a closed polyline, with what the other steps measure on it.
struct BoundaryLoop {
  std::vector<Vec3> points;  // in loop order (closed: the last joins the first), m
  std::vector<uint32_t> vertex;  // the mesh vertex of each point
  std::vector<double> cum;   // arc position of each point from the first, m
  double total = 0;          // the loop's length, m
  double spacing = 0;        // median segment length, m
  // Newell's normal (the sum of its edges' cross products, twice the area the loop
  // encloses): the loop turns anticlockwise about it.
  Vec3 normal = Vec3::Zero();

  size_t size() const { return points.size(); }
  // The point at arc position s (wrapped).
  Vec3 pointAt(double s) const;
  // Whether the loop, arriving along `in` and leaving along `out`, turns outwards.
  bool outwards(const Vec3& in, const Vec3& out) const { return in.cross(out).dot(normal) >= 0; }
};
BoundaryLoop boundaryLoop(const Mesh& mesh);

// The area between two polylines running the same way (an edge's sampled boundary
// and its outline), outwards where `b` lies to the right of `a` seen from `up`, m².
double ribbonArea(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& up);

// ---- corners.cpp: the corners on the boundary loop ----

// Indices into the loop's points; `peak` only with has_peak.
struct NamedCorners {
  size_t tack = 0, clew = 0, head = 0, peak = 0;
  bool has_peak = false;
  std::vector<size_t> picked;    // all of them, for walking between them
  std::vector<double> turn_deg;  // turning angle at each loop point over the corner window
};
NamedCorners findCorners(const BoundaryLoop& loop, const OutlineParams& params);

// The loop's indices from corner `from` to corner `to`, the way that passes no other
// corner (empty when both ways do).
std::vector<size_t> indicesBetween(const BoundaryLoop& loop, const NamedCorners& corners, size_t from, size_t to);
// Their points; throws AnalysisError when both ways pass another corner.
std::vector<Vec3> walkBetween(const BoundaryLoop& loop, const NamedCorners& corners, size_t from, size_t to);

// ---- edges.cpp: the edge model ----

// A smooth edge: a point for each s, in metres of boundary arc from the edge's
// first corner (one polynomial per coordinate).
struct EdgeCurve : Polynomial {
  Vec3 at(double s) const { return Polynomial::at(s).transpose(); }
  Vec3 tangent(double s) const {
    const double h = 1e-4 * scale;
    return (at(s + h) - at(s - h)).normalized();
  }
};
// Least squares through pts at arc positions s, over their range.
EdgeCurve fitEdgeCurve(const std::vector<Vec3>& pts, const std::vector<double>& s, int degree);

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
  // windows' curve, so that curve's scatter cancels out of it, and `sigma` would
  // overstate it.
  double section_sigma = 0;
  double scatter = 0;         // RMS distance of the points from the fitted curve, m
};

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
// along that normal onto the vertices' plane. idx, d2: scratch for the search.
struct Across {
  Vec3 in = Vec3::Zero();
  Vec3 on_surface = Vec3::Zero();
};
Across acrossAt(const Vec3& near, const Vec3& at, const Vec3& t, const Samples& smp, std::vector<uint32_t>& idx,
                std::vector<double>& d2);

// Samples beside an edge as (arc position, offset across it), offsets positive inwards, m.
using AlongOffset = std::vector<std::pair<double, double>>;

// A window of n samples whose offsets are uniform on [−δ, D]: the least lies a
// gap above −δ, E[gap] = (D + δ)/(n + 1), so −least = δ − gap + E[gap], solved for δ.
double recessFromLeast(double least, double D, double n);

// Calls f(a, b) for each run [a, b) of `sorted` (ascending in arc position) that
// starts where the last one ended and reaches less than `window` along from its
// first sample; each holds one sample at least.
template <typename F>
void forEachWindow(const AlongOffset& sorted, double window, F&& f) {
  for (size_t a = 0; a < sorted.size();) {
    size_t b = a + 1;
    while (b < sorted.size() && sorted[b].first < sorted[a].first + window) ++b;
    f(a, b);
    a = b;
  }
}

// The lower envelope of samples (ascending in arc position): the polynomial of at
// most `degree` beyond the outermost sample of every stretch `window` long and as
// far in as that allows; its range is [centre − scale, centre + scale]. nullopt when
// the linear programme has no optimum or the samples are too few.
std::optional<Polynomial> lowerEnvelope(const AlongOffset& along_offset, double window, int degree);

// Fits e.curve through e.points (arc positions e.s) and moves the points out to
// where the surface ends; sets every field of e from `length` on.
void fitEdge(Edge& e, const Samples& smp, double spacing);

// The edge from corner to corner: first, the fitted curve between the excluded
// ends at about `step` spacing, last.
std::vector<Vec3> edgePolyline(const Edge& e, const Vec3& first, const Vec3& last, double step);

// The direction from `corner` to the point a tenth of edge e's length along it
// (from its start when at_start, else from its end).
Vec3 edgeChord(const Edge& e, bool at_start, const Vec3& corner, double spacing);

// ---- corner_curves.cpp: each edge's curve near a corner ----

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
CornerCurve cornerCurve(const Edge& e, bool at_start, double spacing, int degree, bool shorten_if_bent);
double frontierWindow(const CornerCurve& c, bool from_corner, double spacing);
CornerCurve ontoFrontier(const CornerCurve& c, const CornerCurve& other, const Samples& smp, double spacing,
                         bool from_corner);
CornerCurve ontoEnvelope(const CornerCurve& c, const CornerCurve& other, const Samples& smp, double spacing);

// ---- corner_placement.cpp: where two edges meet ----

// How well a corner is placed: 1σ along and across its bisector, and the half
// angle between its edges (how its shifts move the edges' lengths and lines).
struct CornerSpread {
  double along_m = 0, across_m = 0, half_rad = 0;
  double position() const { return std::hypot(along_m, across_m); }
  // σ across one of its edges: the bisector leaves each edge at the half angle.
  double acrossEdge() const { return std::hypot(along_m * std::sin(half_rad), across_m * std::cos(half_rad)); }
};

// What placing a corner needs besides its two edges.
struct CornerContext {
  const Samples& samples;
  const std::vector<Vec3>& loose_points;  // samples the mesh left out (extractOutline)
  double density_per_m2 = 0;               // of the outermost samples
  double reach_m = 0;                      // how far from the edges' crossing samples count
  double spacing_m = 0;                    // boundary spacing
  const OutlineParams& params;
  std::optional<Vec3> footprint_scanner;   // set when the beam footprint moves the corners out
};

// The corner where edges a and b meet (each starting there when *_start), on the
// surface, moved out by the beam's footprint when that applies; `spread` its 1σ.
Vec3 placeCornerBetween(const Edge& a, bool a_start, const Edge& b, bool b_start, const CornerContext& ctx,
                        CornerSpread& spread);

// ---- beam_footprint.cpp: the beam's footprint at the edges ----

// How far the footprint reaches from the beam's axis across the surface at `at`
// (unit normal n) in the surface direction w (unit), for a scanner at `origin`, m.
double footprintReach(const OutlineParams& p, const Vec3& origin, const Vec3& at, const Vec3& n, const Vec3& w);
// How far a corner moves when each of its edges moves out by the footprint's reach.
Vec3 footprintShift(const OutlineParams& p, const Vec3& scanner, const Vec3& corner, const Edge& a, bool a_start,
                    const Edge& b, bool b_start, double spacing);
// Moves an edge polyline's inner points out by the reach there and widens its σ by
// the reach's uncertainty; returns the mean reach, m (0 for fewer than 3 points).
double moveOutByFootprint(std::vector<Vec3>& line, double& sigma, const OutlineParams& p, const Vec3& scanner,
                          const Samples& samples);

// ---- coverage.cpp: where the samples stop, and why ----

// Whether the scan reached each corner and each edge (SailOutline::Coverage), from
// where the scanner stood: a boundary the beams met at grazing incidence, at the end
// of their range, or beyond which they met something else of the `scene` first (its
// points as scanned, the sail's among them; empty: not looked for), is where the scan
// stopped, not where the sail ends.
SailOutline::Coverage scanCoverage(const BoundaryLoop& loop, const NamedCorners& corners, const Samples& samples,
                                   const Vec3& scanner, const std::vector<Vec3>& scene, const OutlineParams& params);

// ---- consistency.cpp: whether the outline is a sail's ----

// Throws AnalysisError in one line when the placed corners break the rules they were
// named by (head highest, tack forward of the clew), an edge is as long as the others
// together, or the head lies nearer the tack than the clew does.
void refuseContradictoryOutline(const SailOutline& outline);

}  // namespace sailshape::outline_internal
