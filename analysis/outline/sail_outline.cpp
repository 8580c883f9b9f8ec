// extractOutline: the boundary loop, its corners, the edges between them, where
// the edges meet, and what the outline reports (lengths, area, uncertainties).
#include "analysis/outline/sail_outline.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "analysis/core/errors.hpp"
#include "analysis/outline/outline_internal.hpp"

namespace sailshape {
namespace {

using namespace outline_internal;

// The sail's edges, each from its first corner: luff tack→head, foot tack→clew,
// leech clew→head (clew→peak with a peak), top head→peak (only with a peak).
struct SailEdges {
  Edge luff, foot, leech, top;
};

// The edge along the loop from corner `from` to corner `to`, fitted and moved out.
Edge edgeBetween(const BoundaryLoop& loop, const NamedCorners& corners, size_t from, size_t to, const Samples& samples) {
  Edge e;
  e.points = walkBetween(loop, corners, from, to);
  e.s.assign(e.points.size(), 0.0);
  for (size_t i = 1; i < e.points.size(); ++i) e.s[i] = e.s[i - 1] + (e.points[i] - e.points[i - 1]).norm();
  fitEdge(e, samples, loop.spacing);
  return e;
}

SailEdges fitEdges(const BoundaryLoop& loop, const NamedCorners& c, const Samples& samples) {
  SailEdges e;
  e.luff = edgeBetween(loop, c, c.tack, c.head, samples);
  e.foot = edgeBetween(loop, c, c.tack, c.clew, samples);
  e.leech = edgeBetween(loop, c, c.clew, c.has_peak ? c.peak : c.head, samples);
  if (c.has_peak) e.top = edgeBetween(loop, c, c.head, c.peak, samples);
  return e;
}

// Each edge's 1σ across it between the corners. An edge beside scan lines lies
// anywhere up to a line spacing beyond the last line (uniform: σ = spacing / √12),
// whatever its fit's own scatter.
void setEdgeSigmas(const SailEdges& e, SailOutline& out) {
  auto reported = [](const Edge& edge) { return std::hypot(edge.section_sigma, edge.line_spacing / std::sqrt(12.0)); };
  out.luff_sigma_m = reported(e.luff);
  out.leech_sigma_m = reported(e.leech);
  out.foot_sigma_m = reported(e.foot);
  if (out.has_peak) out.top_sigma_m = reported(e.top);
}

struct CornerSpreads {
  CornerSpread tack, clew, head, peak;
};

// The corners where the edges meet, and how well each is placed.
CornerSpreads placeCorners(const SailEdges& e, const CornerContext& ctx, SailOutline& out) {
  CornerSpreads at;
  out.tack = placeCornerBetween(e.luff, true, e.foot, true, ctx, at.tack);
  out.clew = placeCornerBetween(e.foot, false, e.leech, true, ctx, at.clew);
  if (out.has_peak) {
    out.head = placeCornerBetween(e.luff, false, e.top, true, ctx, at.head);
    out.peak = placeCornerBetween(e.leech, false, e.top, false, ctx, at.peak);
  } else {
    out.head = placeCornerBetween(e.luff, false, e.leech, false, ctx, at.head);
  }
  out.tack_sigma_m = at.tack.along_m;
  out.clew_sigma_m = at.clew.along_m;
  out.head_sigma_m = at.head.along_m;
  out.peak_sigma_m = at.peak.along_m;
  SailOutline::Uncertainty& u = out.uncertainty;
  u.tack_m = at.tack.position();
  u.clew_m = at.clew.position();
  u.head_m = at.head.position();
  u.peak_m = at.peak.position();
  return at;
}

// A corner beside a narrow shadow lies anywhere across the shadow's width w from
// where its samples stop: uniform, σ = w / √12 joins its place along the bisector.
void widenForShadows(SailOutline& out, CornerSpreads& at) {
  const SailOutline::Coverage& c = out.coverage;
  auto widen = [](double shadow_m, CornerSpread& spread, double& sigma, double& position) {
    if (shadow_m <= 0) return;
    spread.along_m = std::hypot(spread.along_m, shadow_m / std::sqrt(12.0));
    sigma = spread.along_m;
    position = spread.position();
  };
  SailOutline::Uncertainty& u = out.uncertainty;
  widen(c.tack_shadow_m, at.tack, out.tack_sigma_m, u.tack_m);
  widen(c.clew_shadow_m, at.clew, out.clew_sigma_m, u.clew_m);
  widen(c.head_shadow_m, at.head, out.head_sigma_m, u.head_m);
  if (out.has_peak) widen(c.peak_shadow_m, at.peak, out.peak_sigma_m, u.peak_m);
}

void warnOfScanLines(const SailEdges& e, SailOutline& out) {
  for (const auto& [name, edge] : {std::pair<const char*, const Edge*>{"luff", &e.luff}, {"leech", &e.leech},
                                   {"foot", &e.foot}, {"top edge", &e.top}})
    if (edge->line_spacing > 0)
      out.warnings.push_back(
          std::string(name) + ": its samples lie on scan lines running beside it, about " +
          formatFixed(100 * edge->line_spacing, 1) + " cm apart (a cloud without its scan angles?); " +
          (edge->along_lines ? "the edge runs through the lines' ends and between them is known to a line spacing"
                             : "the edge is placed by the last line, up to a line spacing inside it") +
          ", and the corners at its ends may lie further off than that");
}

// The edges' polylines from corner to corner; with the footprint correction, moved
// out by the footprint's reach (the corners are moved already).
void traceEdges(const SailEdges& e, const OutlineParams& p, const std::optional<Vec3>& footprint_scanner,
                const Samples& samples, double spacing, SailOutline& out) {
  out.luff = edgePolyline(e.luff, out.tack, out.head, spacing);
  out.foot = edgePolyline(e.foot, out.tack, out.clew, spacing);
  out.leech = edgePolyline(e.leech, out.clew, out.has_peak ? out.peak : out.head, spacing);
  if (out.has_peak) out.top = edgePolyline(e.top, out.head, out.peak, spacing);
  if (footprint_scanner) {
    const Vec3& scanner = *footprint_scanner;
    const double at_luff = moveOutByFootprint(out.luff, out.luff_sigma_m, p, scanner, samples);
    moveOutByFootprint(out.foot, out.foot_sigma_m, p, scanner, samples);
    const double at_leech = moveOutByFootprint(out.leech, out.leech_sigma_m, p, scanner, samples);
    out.footprint_reach_m = std::max(at_luff, at_leech);
    if (out.has_peak) moveOutByFootprint(out.top, out.top_sigma_m, p, scanner, samples);
  }
  out.luff_length_m = polylineLength(out.luff);
  out.leech_length_m = polylineLength(out.leech);
  out.foot_length_m = polylineLength(out.foot);
  out.top_length_m = polylineLength(out.top);
}

// The sail's area beyond the mesh: between each edge's sampled boundary and its
// outline, corners included (a wide corner's boundary rounds off over half a
// metre, which the edges' recess times their lengths would leave out). Seen from
// the loop's normal each sampled edge runs anticlockwise when it follows the
// loop's order, clockwise when it runs against it. m².
double areaBeyondMesh(const BoundaryLoop& loop, const NamedCorners& c, const SailOutline& out) {
  auto ribbon = [&](size_t from, size_t to, const std::vector<Vec3>& outline) {
    const std::vector<Vec3> sampled = walkBetween(loop, c, from, to);
    const bool with_loop = sampled.size() > 1 && sampled[1] == loop.points[(from + 1) % loop.size()];
    return ribbonArea(sampled, outline, with_loop ? loop.normal : Vec3(-loop.normal));
  };
  double area = ribbon(c.tack, c.head, out.luff) + ribbon(c.tack, c.clew, out.foot) +
                ribbon(c.clew, c.has_peak ? c.peak : c.head, out.leech);
  if (c.has_peak) area += ribbon(c.head, c.peak, out.top);
  return area;
}

// A corner's shift along its bisector moves each of its edges' ends along the
// edge by cos(half angle) of it; an edge's shift across moves the area by its
// length (the edges' σ are mostly their common offset, so taken whole).
void setLengthAndAreaSigmas(const CornerSpreads& at, SailOutline& out) {
  auto lengthSigma = [](const CornerSpread& from, const CornerSpread& to) {
    return std::hypot(from.along_m * std::cos(from.half_rad), to.along_m * std::cos(to.half_rad));
  };
  SailOutline::Uncertainty& u = out.uncertainty;
  u.luff_length_m = lengthSigma(at.tack, at.head);
  u.foot_length_m = lengthSigma(at.tack, at.clew);
  u.leech_length_m = lengthSigma(at.clew, out.has_peak ? at.peak : at.head);
  if (out.has_peak) u.top_length_m = lengthSigma(at.head, at.peak);
  u.luff_line_m = 0.5 * std::hypot(at.tack.acrossEdge(), at.head.acrossEdge());
  u.area_m2 = std::sqrt(std::pow(out.luff_sigma_m * out.luff_length_m, 2) +
                        std::pow(out.leech_sigma_m * out.leech_length_m, 2) +
                        std::pow(out.foot_sigma_m * out.foot_length_m, 2) +
                        std::pow(out.top_sigma_m * out.top_length_m, 2));
}

// Throws when a length is more than design_tolerance off its design value; warns
// when more than design_warning off and beyond 3σ of the measured length.
void checkDesignLengths(const OutlineParams& p, SailOutline& out) {
  if (p.design_lengths_m.empty()) return;
  const SailOutline::Uncertainty& u = out.uncertainty;
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

}  // namespace

void checkOutlineParams(const OutlineParams& p) {
  if (!(p.beam_exit_diameter_m >= 0) || !(p.beam_divergence_rad >= 0) || p.beam_exit_diameter_m > 1 ||
      p.beam_divergence_rad > 0.5)
    throw InvalidInput("[extractOutline] beam_exit_diameter_m must be in [0, 1] and beam_divergence_rad in [0, 0.5] (got " +
                       formatFixed(p.beam_exit_diameter_m, 4) + ", " + formatFixed(p.beam_divergence_rad, 4) + ")");
  if (!(p.grazing_incidence_deg > 0 && p.grazing_incidence_deg <= 90))
    throw InvalidInput("[extractOutline] grazing_incidence_deg must be in (0, 90] (got " +
                       formatFixed(p.grazing_incidence_deg, 1) + ")");
  if (!(p.scanner_position_sigma_m >= 0) || !std::isfinite(p.scanner_position_sigma_m))
    throw InvalidInput("[extractOutline] scanner_position_sigma_m must be >= 0 (got " +
                       formatFixed(p.scanner_position_sigma_m, 3) + ")");
  if (!(p.scanner_max_range_m >= 0) || !std::isfinite(p.scanner_max_range_m))
    throw InvalidInput("[extractOutline] scanner_max_range_m must be >= 0 (0: unknown; got " +
                       formatFixed(p.scanner_max_range_m, 1) + ")");
  if (p.corners != 0 && p.corners != 3 && p.corners != 4)
    throw InvalidInput("[extractOutline] corners must be 0 (auto), 3 or 4 (got " + std::to_string(p.corners) + ")");
  if (!p.design_lengths_m.empty() && p.design_lengths_m.size() != 3)
    throw InvalidInput("[extractOutline] design_lengths_m must be [luff, leech, foot] (got " +
                       std::to_string(p.design_lengths_m.size()) + " values)");
}

SailOutline extractOutline(const Mesh& mesh, const OutlineParams& p, const std::vector<Vec3>& loose_points,
                           double sample_density_per_m2, const std::optional<Vec3>& scanner,
                           const std::vector<Vec3>& scene) {
  if (mesh.triangles.empty()) throw InvalidInput("[extractOutline] empty mesh");
  checkOutlineParams(p);
  SailOutline out;
  const bool beam_given = p.beamGiven();
  if (beam_given && !scanner && !p.edges_against_sky)
    out.warnings.push_back("the beam's footprint is given but not where the scanner stood (the cloud has no viewpoint): "
                           "the edges are not moved out by it");
  const std::optional<Vec3> footprint_scanner =
      beam_given && scanner.has_value() && !p.edges_against_sky ? scanner : std::nullopt;

  const BoundaryLoop loop = boundaryLoop(mesh);
  out.boundary = loop.points;
  out.boundary_spacing_m = loop.spacing;
  const double sp = loop.spacing;
  const NamedCorners corners = findCorners(loop, p);
  out.has_peak = corners.has_peak;
  out.corner_turn_deg = {corners.turn_deg[corners.tack], corners.turn_deg[corners.clew], corners.turn_deg[corners.head]};
  if (out.has_peak) out.corner_turn_deg.push_back(corners.turn_deg[corners.peak]);

  // Fit each edge, move it out to where the surface really ends, and place the
  // corners where neighbouring edges meet (a sharp corner itself is never sampled).
  const std::vector<Vec3> normals = vertexNormals(mesh);
  // Cells about three boundary spacings wide: the 24 nearest vertices of a boundary point lie within two or so.
  const PointGrid tree(mesh.vertices, 3.0 * std::max(sp, 1e-6));
  const Samples samples{mesh, normals, tree};
  if (scanner) out.coverage = scanCoverage(loop, corners, samples, *scanner, scene, p);
  const SailEdges edges = fitEdges(loop, corners, samples);
  setEdgeSigmas(edges, out);

  const double mesh_area = meshArea(mesh);
  const double density = sample_density_per_m2 > 0
                             ? sample_density_per_m2
                             : static_cast<double>(mesh.vertices.size()) / std::max(1e-12, mesh_area);
  const CornerContext ctx{samples, loose_points, density, std::max(0.05 * loop.total, 10.0 * sp), sp, p,
                          footprint_scanner};
  CornerSpreads spreads = placeCorners(edges, ctx, out);
  widenForShadows(out, spreads);
  warnOfScanLines(edges, out);
  traceEdges(edges, p, footprint_scanner, samples, sp, out);
  out.area_m2 = mesh_area + areaBeyondMesh(loop, corners, out);
  setLengthAndAreaSigmas(spreads, out);
  refuseContradictoryOutline(out);
  checkDesignLengths(p, out);
  return out;
}

}  // namespace sailshape
