#include "analysis/pipeline/design_prior.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "analysis/core/errors.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/fit/design_fit.hpp"
#include "analysis/sections/luff_curve.hpp"
#include "analysis/spatial/neighbours.hpp"

namespace sailshape {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

// How far a flying sail's sections may differ from its design's where nothing was seen, 1σ:
// a plausible trim (design_compare.hpp plausibleTrimDeviationM) changes the camber by up to ±5 %
// of the chord and the twist by up to ±10° (sheeting and leech tension), here their 2σ. The
// draft moves with the camber's change by a few % of the chord, and the end angles of a
// parabolic section of camber c lie at atan(4c) to the chord: 4 × 2.5 % → 5.7°.
constexpr SectionParameters kTrimSigma = {0.0, 2.5, 5.0, 5.0, 0.0, 5.7, 5.7};

// The fit at a point of the fitted surface: its nearest fitted vertex's σ (m, along the
// normal), slope σ (rad) and support.
class FitAt {
 public:
  explicit FitAt(const DesignFit& fit) : fit_(fit), tree_(fit.fitted.vertices) {}
  size_t vertex(const Vec3& p) const {
    tree_.nearest(p, 1, idx_, d2_);
    return idx_.empty() ? 0 : idx_[0];
  }
  double sigma(const Vec3& p) const { return fit_.sigma_m[vertex(p)]; }
  double slopeSigma(const Vec3& p) const { return fit_.slope_sigma_rad[vertex(p)]; }
  // At a section's ends the fitted slope is the samples' smoothed over the bending length, pulled
  // towards the design's: by up to the turn between the two where they were seen.
  double endSlopeSigma(const Vec3& p) const { return std::max(slopeSigma(p), fit_.turn_rad); }
  bool supported(const Vec3& p) const { return fit_.supported[vertex(p)] != 0; }

 private:
  const DesignFit& fit_;
  KdTree tree_;
  mutable std::vector<uint32_t> idx_;
  mutable std::vector<double> d2_;
};

// One corner of the outline: where it stands, its σ as a position (reported) and along its
// edge (what moves the sections' ends, SailOutline's *_sigma_m).
struct Corner {
  Vec3* at;
  double* sigma_along;
  double* sigma_reported;
  bool reached;
  double edge_length_m;  // the edge its place along was inferred over
};

// Why the scan alone refused, without the stage's "[name] " prefix.
std::string plainReason(const std::string& what) {
  std::string why = what;
  while (!why.empty() && why.front() == '[') {
    const size_t close = why.find("] ");
    if (close == std::string::npos) break;
    why.erase(0, close + 2);
  }
  return why;
}

// The fit's own error on a section cut on the fitted surface: the surface's place along its
// normal (σ_n) moves the crest against the chord line and the chord's ends across it, and its
// slope's σ turns the ends' tangents and moves the crest along the chord. Added in quadrature
// to what cutSections found on the fitted surface as if it were measured.
void addFitUncertainty(Section& s, const FitAt& fit, const Section* design) {
  size_t inferred = 0;
  for (const Vec3& p : s.curve) inferred += fit.supported(p) ? 0 : 1;
  s.inferred_pct = s.curve.empty() ? 0.0 : 100.0 * static_cast<double>(inferred) / static_cast<double>(s.curve.size());
  SectionParameters& u = s.uncertainty;
  const double chord = std::max(1e-9, s.value.chord_m);
  const double sl = fit.sigma(s.luff_point), se = fit.sigma(s.leech_point), sm = fit.sigma(s.max_camber_point);
  // The chord line moves by about half its ends' shift at the crest (as sections.cpp has it).
  u.camber_pct = std::hypot(u.camber_pct, 100.0 * std::hypot(sm, 0.5 * std::hypot(sl, se)) / chord);
  // A slope error s at the crest of a parabolic section of depth D moves the crest along the
  // chord by s·c²/(8D): in % of the chord, 100·s/(8·camber).
  const double camber = std::max(0.01, s.value.camber_pct / 100.0);
  u.draft_pct = std::hypot(u.draft_pct, 100.0 * fit.slopeSigma(s.max_camber_point) / (8.0 * camber));
  const Vec3 chord_vec = s.leech_point - s.luff_point;
  const double chord_xy = std::hypot(chord_vec.x(), chord_vec.y());
  u.twist_deg = chord_xy > 0 ? std::hypot(u.twist_deg, std::hypot(sl, se) / chord_xy * kDegPerRad) : 180.0;
  if (std::isfinite(u.entry_deg)) u.entry_deg = std::hypot(u.entry_deg, fit.endSlopeSigma(s.luff_point) * kDegPerRad);
  if (std::isfinite(u.exit_deg)) u.exit_deg = std::hypot(u.exit_deg, fit.endSlopeSigma(s.leech_point) * kDegPerRad);
  // Where the samples do not hold the fitted surface, the flying sail is its design at some
  // plausible trim: a section lies no farther from the truth than from the design's section plus
  // a plausible trim (B). The fit's σ above knows the surface point by point, not how a section's
  // crest and ends move with a shape the samples never constrained: the share w of the curve that
  // was inferred carries w·B, and B bounds the whole (far from the samples the fit's σ grows
  // without bound, the flying sail's difference from its design does not).
  if (!design) return;
  const double w = s.inferred_pct / 100.0;
  auto bound = [w](double& sigma, double value, double design_value, double trim) {
    if (!std::isfinite(value) || !std::isfinite(design_value)) return;
    const double b = std::abs(value - design_value) + trim;
    sigma = std::min(std::hypot(sigma, w * b), b);
  };
  const SectionParameters &v = s.value, &d = design->value;
  bound(u.camber_pct, v.camber_pct, d.camber_pct, kTrimSigma.camber_pct);
  bound(u.draft_pct, v.draft_pct, d.draft_pct, kTrimSigma.draft_pct);
  bound(u.twist_deg, v.twist_deg, d.twist_deg, kTrimSigma.twist_deg);
  bound(u.entry_deg, v.entry_deg, d.entry_deg, kTrimSigma.entry_deg);
  bound(u.exit_deg, v.exit_deg, d.exit_deg, kTrimSigma.exit_deg);
}

// An edge from a corner to the next: the scan's own where it reached both; from a reached corner
// to one it did not reach, the scan's up to where it stopped and the fitted design's on from its
// point nearest that stop (the fitted design's edge may stand centimetres beside the sail's,
// tangentially unconstrained by the samples); the fitted design's alone where the scan's stop
// lies farther than `bound` from it, or the first corner was not reached either.
// `scanned_m` receives the arc length from the first corner that is the scan's (0: none).
std::vector<Vec3> composeEdge(const std::vector<Vec3>& measured, const std::vector<Vec3>& fitted, bool from_reached,
                              bool to_reached, double bound, double& scanned_m) {
  scanned_m = 0;
  if (!from_reached || measured.size() < 2 || fitted.size() < 2) return fitted;
  scanned_m = polylineLength(measured);
  if (to_reached) return measured;
  const Vec3& stop = measured.back();
  size_t nearest = 0;
  for (size_t i = 1; i < fitted.size(); ++i)
    if ((fitted[i] - stop).squaredNorm() < (fitted[nearest] - stop).squaredNorm()) nearest = i;
  if ((fitted[nearest] - stop).norm() > bound || nearest + 1 >= fitted.size()) {
    scanned_m = 0;
    return fitted;
  }
  std::vector<Vec3> out = measured;
  out.insert(out.end(), fitted.begin() + static_cast<std::ptrdiff_t>(nearest) + 1, fitted.end());
  return out;
}

// Without the scanner's position the outline cannot tell where the scan merely stopped, and
// puts a corner there; with it, it cannot tell a crop or a gap in the cloth from the sail's
// end. The design can: a luff or leech shorter than the design's by more than stretch and
// tension explain (sail_region.hpp edgeBeyondDesign), under a foot as long as the design's,
// ends where the scan did, short of the head. (A foot short too is another, smaller sail, or
// the wrong design: designMismatch's to say.) Marks the head (and peak) not reached and says
// why; "" when the edges stand.
std::string shortOfTheDesign(SailOutline& o, const SailOutline& design) {
  if (edgeBeyondDesign(o.foot_length_m, design.foot_length_m, o.uncertainty.foot_length_m) != 0) return "";
  const struct {
    const char* name;
    double flying_m, design_m, sigma_m;
  } edges[] = {{"luff", o.luff_length_m, design.luff_length_m, o.uncertainty.luff_length_m},
               {"leech", o.leech_length_m, design.leech_length_m, o.uncertainty.leech_length_m}};
  std::string why;
  for (const auto& e : edges)
    if (edgeBeyondDesign(e.flying_m, e.design_m, e.sigma_m) < 0)
      why += std::string(why.empty() ? "" : ", ") + "its " + e.name + " measured " + formatFixed(e.flying_m, 2) +
             " m against the design's " + formatFixed(e.design_m, 2) + " m";
  if (why.empty()) return "";
  why += ": the scan did not reach the head";
  o.coverage.known = true;
  o.coverage.head = false;
  if (o.has_peak) o.coverage.peak = false;
  o.coverage.unreached.push_back("the head: " + why);
  return why;
}

}  // namespace

SailAnalysis analyzeWithDesign(const Cloud& scan, const RegionBox& region, const Mesh& design,
                               const MeshSections& design_sections, const AnalysisParams& params,
                               const Progress& progress) {
  SailAnalysis partial;
  std::string why;
  try {
    SailAnalysis a = analyzeInRegion(scan, region, design, params, progress, &partial);
    why = shortOfTheDesign(a.outline, design_sections.outline);
    if (why.empty()) return a;
    a.sections = SectionAnalysis{};
    partial = std::move(a);
  } catch (const AnalysisError& e) {
    if (partial.sail_cloud.empty() || partial.mesh.empty()) throw;  // no sail surface to fit the design to
    why = plainReason(e.what());
  }

  const auto start = std::chrono::steady_clock::now();
  DesignFitParams fp;
  fp.sensor_sigma_m = params.sensor_sigma_m;
  DesignFit fit = fitDesign(design, partial.sail_cloud.points, fp, progress);
  if (fit.samples_used < fit.samples / 2)
    throw AnalysisError("[analyzeWithDesign] " + why + "; and the design does not fit the scan either: only " +
                        std::to_string(fit.samples_used) + " of its " + std::to_string(fit.samples) +
                        " sail points lie on the fitted design within the noise");

  // The fitted design measured as a design is (analyzeMeshSections): sampled evenly and meshed
  // again, so a coarse export's facets do not become the sections' shape.
  progress("sections on the fitted design", 0.0);
  const Mesh fitted_surface = resampleMesh(fit.fitted);
  OutlineParams op = params.outline;
  op.design_lengths_m.clear();  // the design's own: nothing to check
  op.beam_exit_diameter_m = op.beam_divergence_rad = 0;
  op.scanner_max_range_m = 0;
  SailOutline o = extractOutline(fitted_surface, op);

  // The scan's own outline, when the refusal came after it: the corners it reached stand
  // where it measured them.
  const SailOutline& measured = partial.outline;
  const bool have_measured = measured.coverage.known && !measured.boundary.empty();
  // A scan cut off across the top may show a fourth corner the design has not, or miss one it
  // has: its head and peak then are not the design's.
  const bool same_corners = have_measured && measured.has_peak == o.has_peak;
  const FitAt at(fit);
  // An inferred corner's place along its edge is the design's, stretched as the cloth may: 3σ
  // at the fit's plausible strain.
  const double strain_sigma = fp.max_plausible_strain_pct / 300.0;
  SailOutline::Uncertainty& ou = o.uncertainty;
  const SailOutline::Uncertainty& mu = measured.uncertainty;
  const SailOutline::Coverage& mc = measured.coverage;
  const bool reached[] = {have_measured && mc.tack, have_measured && mc.clew, same_corners && mc.head,
                          same_corners && mc.peak && o.has_peak};
  Corner corners[] = {
      {&o.tack, &o.tack_sigma_m, &ou.tack_m, reached[0], o.luff_length_m},
      {&o.clew, &o.clew_sigma_m, &ou.clew_m, reached[1], o.foot_length_m},
      {&o.head, &o.head_sigma_m, &ou.head_m, reached[2], o.luff_length_m},
      {&o.peak, &o.peak_sigma_m, &ou.peak_m, reached[3], o.leech_length_m},
  };
  const Vec3 measured_at[] = {measured.tack, measured.clew, measured.head, measured.peak};
  const double measured_along[] = {measured.tack_sigma_m, measured.clew_sigma_m, measured.head_sigma_m,
                                   measured.peak_sigma_m};
  const double measured_reported[] = {mu.tack_m, mu.clew_m, mu.head_m, mu.peak_m};
  const SailOutline& d = design_sections.outline;
  const Vec3 design_at[] = {d.tack, d.clew, d.head, d.peak};
  // A corner not seen lies no farther from the truth than from the design's corner plus a
  // plausible trim (taken as 2σ).
  const double trim_sigma = 0.5 * plausibleTrimDeviationM(design);
  std::vector<std::string> inferred_corners;
  const char* names[] = {"tack", "clew", "head", "peak"};
  for (int c = 0; c < 4; ++c) {
    if (c == 3 && !o.has_peak) continue;
    Corner& k = corners[c];
    if (k.reached && measured_at[c].allFinite()) {
      *k.at = measured_at[c];
      *k.sigma_along = measured_along[c];
      *k.sigma_reported = measured_reported[c];
    } else {
      const double bound = (c < 3 || d.has_peak) ? (*k.at - design_at[c]).norm() + trim_sigma : HUGE_VAL;
      const double along = std::min(strain_sigma * k.edge_length_m, bound);
      *k.sigma_along = along;
      *k.sigma_reported = std::min(std::hypot(at.sigma(*k.at), along), bound);
      inferred_corners.push_back(names[c]);
    }
  }
  // The edges: the scan's where it reached them.
  double luff_scanned_m = 0, leech_scanned_m = 0;
  if (have_measured) {
    const bool top_reached = o.has_peak ? reached[3] : reached[2];
    const double bound = 2 * trim_sigma;
    double unused = 0;
    o.luff = composeEdge(measured.luff, o.luff, reached[0], reached[2], bound, luff_scanned_m);
    o.leech = composeEdge(measured.leech, o.leech, reached[1], top_reached, bound, leech_scanned_m);
    o.foot = composeEdge(measured.foot, o.foot, reached[0], reached[1], bound, unused);
    if (o.has_peak && same_corners) o.top = composeEdge(measured.top, o.top, reached[2], reached[3], bound, unused);
  }
  // The edges run between the corners as they now stand.
  auto setEnds = [](std::vector<Vec3>& line, const Vec3& from, const Vec3& to) {
    if (line.size() < 2) return;
    line.front() = from;
    line.back() = to;
  };
  setEnds(o.luff, o.tack, o.head);
  setEnds(o.foot, o.tack, o.clew);
  setEnds(o.leech, o.clew, o.has_peak ? o.peak : o.head);
  if (o.has_peak) setEnds(o.top, o.head, o.peak);
  o.luff_length_m = polylineLength(o.luff);
  o.leech_length_m = polylineLength(o.leech);
  o.foot_length_m = polylineLength(o.foot);
  if (o.has_peak) o.top_length_m = polylineLength(o.top);
  ou.luff_length_m = std::hypot(o.tack_sigma_m, o.head_sigma_m);
  ou.leech_length_m = std::hypot(o.clew_sigma_m, o.has_peak ? o.peak_sigma_m : o.head_sigma_m);
  ou.foot_length_m = std::hypot(o.tack_sigma_m, o.clew_sigma_m);
  if (o.has_peak) ou.top_length_m = std::hypot(o.head_sigma_m, o.peak_sigma_m);
  // The unseen part's area stretches as its edges may, in both directions.
  const double unseen = 1.0 - fit.coverage;
  ou.area_m2 = std::hypot(ou.area_m2, 2.0 * strain_sigma * unseen * o.area_m2);

  // A section whose ends lie on the scan's own edges and whose plane spans the scan's surface is
  // measured there, as the scan alone measures it; the rest are cut on the fitted design.
  SectionAnalysis on_scan;
  if (luff_scanned_m > 0 && leech_scanned_m > 0) {
    try {
      on_scan = cutSections(partial.mesh, o, sectionParamsFor(params, partial));
    } catch (const AnalysisError&) {
      // No section spans the scan's surface: all come from the fitted design.
    }
  }
  const double luff_m = polylineLength(o.luff), leech_m = polylineLength(o.leech);
  auto endsScanned = [&](double t) { return t * luff_m <= luff_scanned_m && t * leech_m <= leech_scanned_m; };
  SectionParams sections = params.sections;
  sections.sensor_sigma_m = params.sensor_sigma_m;
  // The fitted surface stands about the true one by its σ where the samples hold it.
  std::vector<double> supported_sigma;
  for (size_t v = 0; v < fit.sigma_m.size(); ++v)
    if (fit.supported[v]) supported_sigma.push_back(fit.sigma_m[v]);
  if (!supported_sigma.empty()) {
    std::nth_element(supported_sigma.begin(), supported_sigma.begin() + supported_sigma.size() / 2, supported_sigma.end());
    sections.surface_sigma_m = supported_sigma[supported_sigma.size() / 2];
  }
  SectionAnalysis cut = cutSections(fitted_surface, o, sections);
  for (Section& s : cut.sections) {
    auto scanned = std::find_if(on_scan.sections.begin(), on_scan.sections.end(),
                                [&](const Section& x) { return std::abs(x.fraction - s.fraction) < 1e-9; });
    if (scanned != on_scan.sections.end() && endsScanned(s.fraction)) {
      s = *scanned;
      continue;
    }
    const Section* ds = nullptr;
    for (const Section& x : design_sections.sections.sections)
      if (std::abs(x.fraction - s.fraction) < 1e-9) ds = &x;
    addFitUncertainty(s, at, ds);
  }
  for (const std::string& w : on_scan.warnings) cut.warnings.push_back("on the scan's surface: " + w);
  // Sections from the scan's surface and from the fitted design, each relative to its own lowest:
  // relative to the lowest of the mix now.
  setTwistRelative(cut.sections);

  SailAnalysis a = std::move(partial);
  if (have_measured) {
    o.coverage = measured.coverage;
    // Its stops follow the scan's boundary, not the fitted design's.
    o.coverage.boundary_stop.clear();
  }
  if (!have_measured) o.coverage.unreached = {"where the scan reached the sail's edges: " + why};
  o.coverage.known = true;  // as far as the scan and the design tell it
  o.coverage.tack = reached[0];
  o.coverage.clew = reached[1];
  o.coverage.head = reached[2];
  o.coverage.peak = !o.has_peak || reached[3];
  o.warnings.insert(o.warnings.begin(), measured.warnings.begin(), measured.warnings.end());
  a.outline = std::move(o);
  a.luff = measureLuffCurve(a.outline);
  a.sections = std::move(cut);
  std::string list;
  for (size_t i = 0; i < inferred_corners.size(); ++i)
    list += (i == 0 ? "" : i + 1 == inferred_corners.size() ? " and " : ", ") + inferred_corners[i];
  StageReport stage;
  stage.name = "design fit";
  stage.points_in = fit.samples;
  stage.points_out = fit.samples_used;
  stage.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stage.warnings = fit.warnings;
  stage.warnings.insert(stage.warnings.begin(),
                        "the scan alone gave no sections (" + why + "); " +
                            (list.empty() ? std::string("no corner") : "the " + list) +
                            " and the surface beyond the last samples are the design's, fitted to them (" +
                            formatFixed(100 * fit.coverage, 0) + " % of its area within " +
                            formatFixed(1000 * fit.support_radius_m, 0) + " mm of a sample)");
  for (const std::string& w : stage.warnings) a.warnings.push_back("design fit: " + w);
  for (const std::string& w : a.sections.warnings) a.warnings.push_back("sections: " + w);
  a.stages.push_back(std::move(stage));
  a.inferred_because = why;
  a.design_fit = std::move(fit);
  refuseImplausibleResults(a);
  progress("sections on the fitted design", 1.0);
  return a;
}

}  // namespace sailshape
