#pragma once
// Sections and their shape parameters: the contract of SPEC §5.
#include <map>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/outline/sail_outline.hpp"

namespace sailshape {

struct SectionParams {
  int count = 3;                      // t = k/(count+1), k = 1..count
  std::vector<double> fractions;      // explicit fractions in (0, 1); override count when set
  // "normal": start perpendicular to the corners' plane, then rotate about the
  // chord until the plane holds the surface normal at maximum camber;
  // "perpendicular": the start plane only; "horizontal": z = const through the luff point.
  std::string plane = "normal";
  double end_window = 0.10;           // fraction of chord for the entry/exit quadratic fits
  double peak_window = 0.15;          // ± fraction of chord for the cubic fit at maximum camber
  double normal_tolerance_deg = 0.1;  // out-of-plane angle of the surface normal accepted as "contains"
  double max_tilt_deg = 45.0;         // limit of the rotation about the chord
  int max_iterations = 20;
  double normal_radius = 0.05;        // fraction of chord averaged for the surface normal
  double sensor_sigma_m = 0.004;      // SPEC §3 random error, for the uncertainties
  // Length over which the curve's noise is correlated (the smoothing radius; 0:
  // independent points). Fit uncertainties count one independent sample per length.
  double noise_correlation_m = 0.0;
  // 1σ of the (smoothed) surface about the true one: the least residual σ the
  // entry and exit fits assume. Their cut points follow the smoothed surface, whose
  // error is smooth over noise_correlation_m and hides in a quadratic's residuals.
  // 0: the residuals alone. The pipeline sets it from the smoothing.
  double surface_sigma_m = 0.0;
  int curve_points = 61;              // points of the output curve
  // A hole in the scan (an occlusion by a sheet or spar, a dropout) breaks the
  // section curve. Gaps up to 10 % of the chord are read as they are; inside
  // the chord, wider ones up to this fraction are bridged by a cubic that keeps
  // the slopes on either side, with a warning and the bridge's own uncertainty.
  // A curve that leaves over 10 % uncovered at an end, or crosses a wider hole,
  // leaves its section unmeasured (the others stand); the entry and exit fits
  // read measured points only, never a bridge's.
  double max_bridged_gap = 0.35;
};

// Per-section parameters; also used for their uncertainties (1σ, same units).
struct SectionParameters {
  double chord_m = 0;
  double camber_pct = 0;
  double draft_pct = 0;
  double twist_deg = 0;
  double twist_rel_deg = 0;
  double entry_deg = 0;
  double exit_deg = 0;
};

struct Section {
  double fraction = 0;
  Vec3 luff_point = Vec3::Zero(), leech_point = Vec3::Zero();
  SectionParameters value, uncertainty;
  Vec3 max_camber_point = Vec3::Zero();
  Vec3 plane_normal = Vec3::UnitZ();
  double plane_tilt_deg = 0;          // rotation about the chord from the start plane
  bool converged = true;              // the normal search met its tolerance
  std::vector<Vec3> curve;            // boat frame, luff to leech
  size_t curve_samples = 0;           // cut points the parameters were computed from
  double bridged_pct = 0;             // % of the chord bridged across holes (see max_bridged_gap)
  // % of the curve on surface inferred from the sail's design, beyond the scan's samples
  // (analysis/pipeline/design_prior.hpp); 0 for a section of the scan alone.
  double inferred_pct = 0;
  // Values this section could not measure, by name ("entry_deg"), with why; each is NaN in
  // `value` and `uncertainty`, and is no result.
  std::map<std::string, std::string> not_measured;
};

// A section asked for that could not be measured, and why: its plane found no
// curve spanning the chord (a hole too wide to bridge, an end of the sail not
// scanned), or it has no chord (a horizontal plane that misses the leech).
struct UnmeasuredSection {
  double fraction = 0;
  std::string reason;                 // "the section plane at fraction 0.750 leaves 14 % of the chord ..."
};

struct SectionAnalysis {
  std::vector<Section> sections;      // the measured ones, ordered by fraction
  std::vector<UnmeasuredSection> unmeasured;  // the rest of those asked for, ordered by fraction
  std::vector<std::string> warnings;
};

// The fractions `params` asks for, validated and sorted.
std::vector<double> sectionFractions(const SectionParams& params);

// Throws InvalidInput for bad parameters (cutSections checks them first; the
// pipeline before it starts).
void checkSectionParams(const SectionParams& params);

// Each section the parameters ask for, measured or (with a warning) unmeasured.
// twist_rel is relative to the lowest measured section. Throws InvalidInput for
// bad parameters and AnalysisError when no section can be measured.
SectionAnalysis cutSections(const Mesh& mesh, const SailOutline& outline, const SectionParams& params = {});

// Each section's twist_rel (value and σ) from its twist and the first's, the lowest: `sections`
// ordered by fraction, as cutSections leaves them.
void setTwistRelative(std::vector<Section>& sections);

// Where the plane through `point` with unit `normal` cuts the mesh: polylines of
// points on the mesh's edges, chained through the edges the cut triangles share
// (open ones first, then loops). Each point lies on the curved edge the vertex
// normals describe (the cubic leaving each end in its tangent plane), not on the
// straight one, which sags below a curved surface. Empty when the plane misses.
std::vector<std::vector<Vec3>> planeCuts(const Mesh& mesh, const Vec3& point, const Vec3& normal);

// Twist per SPEC §5: angle in the XY plane between +X and the chord vector from
// leech to luff, degrees in [0, 180].
double twistDeg(const Vec3& luff_point, const Vec3& leech_point);

}  // namespace sailshape
