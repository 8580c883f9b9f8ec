#pragma once
// The sail's outline on its mesh (SPEC §4 step 6): boundary = edges used by one
// triangle; corners = the 3 (or 4 for square-top sails) boundary points with the
// sharpest turning; luff, leech, foot (and top) are the boundary between them.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"

namespace sailshape {

struct OutlineParams {
  int corners = 0;                    // 0: auto (3, or 4 when a 4th turns enough), 3 or 4
  double corner_window_m = 0.0;       // arm length for the turning angle; 0: 1 % of the boundary length
  // auto: a 4th corner turns at least this over twice the corner window, and half of it over the window
  double min_fourth_corner_deg = 40;
  // Design lengths [luff, leech, foot] in metres to check against (empty: no check);
  // more than design_tolerance off stops the analysis (SPEC §4 step 6); more than
  // design_warning off, and beyond 3σ of the measured length, is a warning: a flying
  // edge stretches by a percent or two, while a scan that does not reach a corner
  // (or whose beam footprint trims a narrow head) reads several percent short, and
  // its sections then sit at fractions of the edges as measured.
  std::vector<double> design_lengths_m;
  double design_tolerance = 0.10;
  double design_warning = 0.02;
  // The scanner's beam (SPEC §3: exit diameter 8-13 mm, divergence 4.6-15 mrad,
  // full angle). A return lies on the sail only while the beam's whole footprint
  // does (one straddling an edge gives a mixed pixel, between sail and background,
  // which the cleaning removes), so the samples stop short of every edge by the
  // footprint's reach across it: exit/2 + range·divergence/2, stretched by the
  // incidence. With both > 0 and the scanner's position known (the cloud's
  // viewpoint), the edges and corners are moved out by that reach. 0: no correction
  // (a cloud of unknown origin, or merged from several units).
  double beam_exit_diameter_m = 0;
  double beam_divergence_rad = 0;
  // Nothing but open sky behind the sail's edges (a sail scanned on the water). A
  // beam straddling an edge then has no background to mix with: it returns from
  // the sail alone while enough of it lies there, and is lost beyond (the study,
  // §4: no mixed pixels against the sky). The samples reach the edges, as far as
  // the beam's axis, and the footprint moves nothing. Leave it false in a wind
  // tunnel, where the walls lie behind, as they do in the built-in emulator's scene.
  bool edges_against_sky = false;
  bool beamGiven() const { return beam_exit_diameter_m != 0 || beam_divergence_rad != 0; }
  // Where a scan stops without the sail ending (SPEC §3): beyond this incidence the
  // cloth returns less and less and, at grazing angles, nothing; beyond the scanner's
  // range nothing at all (0: the range is not known; a scanner model sets it). A
  // boundary met at either, seen from the cloud's viewpoint, is where the scan
  // stopped, and a corner there was not reached.
  double grazing_incidence_deg = 70;
  double scanner_max_range_m = 0;
  // 1σ of the scanner's position when it was estimated rather than known (m; 0:
  // known). A boundary point r away then has its incidence uncertain by about σ/r
  // rad and its range by σ: both limits above are met 2σ sooner, so that doubt
  // about the scanner leans towards "the scan stopped here", never towards a corner.
  double scanner_position_sigma_m = 0;
};

struct SailOutline {
  std::vector<Vec3> boundary;         // the outer boundary loop, as found on the mesh
  Vec3 tack = Vec3::Zero(), clew = Vec3::Zero(), head = Vec3::Zero(), peak = Vec3::Zero();
  bool has_peak = false;              // square-top sail: head (luff side) and peak (leech side)
  std::vector<double> corner_turn_deg;  // turning angle at tack, clew, head (, peak), outwards (> 0)
  // Edge polylines (the fitted edge curves) from corner to corner: luff tack→head, leech
  // clew→head (clew→peak with a peak), foot tack→clew, top head→peak.
  std::vector<Vec3> luff, leech, foot, top;
  double luff_length_m = 0, leech_length_m = 0, foot_length_m = 0, top_length_m = 0;
  double area_m2 = 0;
  double boundary_spacing_m = 0;      // median boundary segment length
  // 1σ position uncertainty across the fitted luff and leech between the corners
  // (from the boundary points' scatter about the fit and the recess estimate, or
  // the samples' lower envelope the curve runs on), metres.
  double luff_sigma_m = 0, leech_sigma_m = 0;
  // 1σ of each corner's place along its bisector (the edges' crossing, narrowed by
  // how far the samples reach), metres. A section's ends sit at arc fractions from
  // the corners, so these move them along the luff and leech.
  double tack_sigma_m = 0, clew_sigma_m = 0, head_sigma_m = 0, peak_sigma_m = 0;
  // The same across the foot and the top edge.
  double foot_sigma_m = 0, top_sigma_m = 0;
  // 1σ of what the outline reports, from the corners' and edges' σ above: each
  // corner's position (along its bisector, and across it as its two edges move
  // sideways), each edge's length (its corners' shifts along it) and the area (the
  // edges' shifts across their lengths).
  struct Uncertainty {
    double tack_m = 0, clew_m = 0, head_m = 0, peak_m = 0;
    double luff_length_m = 0, leech_length_m = 0, foot_length_m = 0, top_length_m = 0;
    double area_m2 = 0;
    double luff_line_m = 0;  // the tack-head line at mid-luff, across the luff (the luff curve's sags are measured from it)
  } uncertainty;
  // How far the beam's footprint kept the samples from the luff and leech (their
  // mean reach, the larger; OutlineParams beam_*), m; 0 without that correction. A
  // section's curve may stop this much further from its ends than a sampled one.
  double footprint_reach_m = 0;
  // What the scan covered, told from where the scanner stood (the cloud's viewpoint).
  struct Coverage {
    bool known = false;  // false: no viewpoint, so where the scan merely stopped cannot be told
    // Each corner reached: the boundary beside it is where the sail ends, not where
    // the beams grazed the cloth or ran out of range.
    bool tack = true, clew = true, head = true, peak = true;
    // The width of a narrow shadow beside a reached corner (a mast or stay in the way
    // of its edges), which the sail's edge lies within; its σ carries it, m (0: none).
    double tack_shadow_m = 0, clew_shadow_m = 0, head_shadow_m = 0, peak_shadow_m = 0;
    // The fraction of each edge's sampled boundary where the sail ends (the rest is
    // where the scan stopped), in [0, 1].
    double luff = 1, leech = 1, foot = 1, top = 1;
    // Why a corner was not reached, one sentence per corner ("the head: ..."); empty when all were.
    std::vector<std::string> unreached;
    // Why the samples stop at each point of SailOutline::boundary (same order); empty
    // when coverage is not known. LeftOut: they do not; more of the sail's samples lie
    // beyond, left out of the surface.
    enum class Stop : uint8_t { Edge, Grazing, Range, Shadow, LeftOut };
    std::vector<Stop> boundary_stop;
    bool allCornersReached() const { return tack && clew && head && peak; }
    // Where the boundary point nearest `point` and the five each side of it along the
    // boundary mostly stop short of the sail's edge (grazing, range, shadow, left out): why, as
    // "the samples stop ..."; nothing where they stop at the edge or coverage is not known.
    std::optional<std::string> shortOfEdgeNear(const std::vector<Vec3>& boundary, const Vec3& point) const;
  } coverage;
  std::vector<std::string> warnings;
};

// Throws InvalidInput for bad parameters (extractOutline checks them first; the
// pipeline before it starts).
void checkOutlineParams(const OutlineParams& params);

// Throws AnalysisError when the mesh has no boundary loop, the corners cannot be
// told apart, or a length is more than design_tolerance off its design value.
// `loose_points`: points of the sail the mesh left out (a lone sample near a
// narrow tip whose triangles were trimmed as too long); a corner reaches at
// least to those of them that lie inside both its edges and on the surface.
// `sample_density_per_m2`: the density the outermost samples near a corner were
// taken at, when the loose points are the scan's own and the mesh's vertices are
// fewer (voxel means); 0: the mesh's vertices per square metre. `scanner`: where the
// samples were measured from (the beam footprint correction needs it).
// `scene`: every sample the scanner took (the sail's among them), in the mesh's frame: a
// boundary beyond which the beams met one of them first is the shadow of what stood in
// the way, not the sail's edge (SailOutline::coverage; empty: shadows are not looked for).
SailOutline extractOutline(const Mesh& mesh, const OutlineParams& params = {},
                           const std::vector<Vec3>& loose_points = {}, double sample_density_per_m2 = 0,
                           const std::optional<Vec3>& scanner = std::nullopt, const std::vector<Vec3>& scene = {});

// Length of a polyline, m.
double polylineLength(const std::vector<Vec3>& line);
// The point at `fraction` (0..1) of a polyline's arc length.
Vec3 pointAtFraction(const std::vector<Vec3>& line, double fraction);

}  // namespace sailshape
