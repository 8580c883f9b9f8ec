#include "analysis/pipeline/analysis_json.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

namespace sailshape {
namespace {

nlohmann::json vec(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

// JSON has no NaN: a value that could not be measured is null.
nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::json sectionParametersToJson(const SectionParameters& p) {
  return {{"chord_m", num(p.chord_m)},         {"camber_pct", num(p.camber_pct)}, {"draft_pct", num(p.draft_pct)},
          {"twist_deg", num(p.twist_deg)},     {"twist_rel_deg", num(p.twist_rel_deg)},
          {"entry_deg", num(p.entry_deg)},     {"exit_deg", num(p.exit_deg)}};
}

nlohmann::json sectionToJson(const Section& s) {
  nlohmann::json j = sectionParametersToJson(s.value);
  j["fraction"] = s.fraction;
  j["luff_point"] = vec(s.luff_point);
  j["leech_point"] = vec(s.leech_point);
  j["uncertainty"] = sectionParametersToJson(s.uncertainty);
  j["max_camber_point"] = vec(s.max_camber_point);
  j["plane_normal"] = vec(s.plane_normal);
  j["plane_tilt_deg"] = s.plane_tilt_deg;
  j["converged"] = s.converged;
  j["bridged_pct"] = s.bridged_pct;
  j["inferred_pct"] = s.inferred_pct;
  if (!s.not_measured.empty()) j["not_measured"] = s.not_measured;  // name → why; those values are null
  nlohmann::json curve = nlohmann::json::array();
  for (const Vec3& p : s.curve) curve.push_back(vec(p));
  j["curve"] = std::move(curve);
  return j;
}

nlohmann::json unmeasuredSectionsToJson(const std::vector<UnmeasuredSection>& unmeasured) {
  nlohmann::json out = nlohmann::json::array();
  for (const UnmeasuredSection& u : unmeasured) out.push_back({{"fraction", u.fraction}, {"reason", u.reason}});
  return out;
}

nlohmann::json analysisToJson(const SailAnalysis& a) {
  nlohmann::json j;
  const SailOutline& o = a.outline;
  nlohmann::json corners = {{"tack", vec(o.tack)}, {"clew", vec(o.clew)}, {"head", vec(o.head)}};
  if (o.has_peak) corners["peak"] = vec(o.peak);
  j["sail"] = {{"corners", corners},
               {"tack", vec(o.tack)},
               {"clew", vec(o.clew)},
               {"head", vec(o.head)},
               {"luff_length_m", o.luff_length_m},
               {"leech_length_m", o.leech_length_m},
               {"foot_length_m", o.foot_length_m},
               {"area_m2", o.area_m2},
               {"corner_count", o.has_peak ? 4 : 3}};
  const SailOutline::Uncertainty& ou = o.uncertainty;
  nlohmann::json sail_sigma = {{"tack_m", ou.tack_m},
                               {"clew_m", ou.clew_m},
                               {"head_m", ou.head_m},
                               {"luff_length_m", ou.luff_length_m},
                               {"leech_length_m", ou.leech_length_m},
                               {"foot_length_m", ou.foot_length_m},
                               {"area_m2", ou.area_m2}};
  if (o.has_peak) {
    j["sail"]["peak"] = vec(o.peak);
    j["sail"]["top_length_m"] = o.top_length_m;
    sail_sigma["peak_m"] = ou.peak_m;
    sail_sigma["top_length_m"] = ou.top_length_m;
  }
  // Where the samples stop because the sail ends, as a fraction of each edge's
  // sampled boundary (the rest: grazing incidence or the end of the range); null
  // without the scanner's position, when that cannot be told.
  const SailOutline::Coverage& cov = o.coverage;
  if (cov.known) {
    j["sail"]["coverage"] = {{"luff", cov.luff}, {"leech", cov.leech}, {"foot", cov.foot}};
    if (o.has_peak) j["sail"]["coverage"]["top"] = cov.top;
  } else {
    j["sail"]["coverage"] = nullptr;
  }
  // Where the scanner stood when the cloud did not say and its density told it
  // (the coverage above was read from there); null otherwise.
  if (const auto& e = a.viewpoint_estimate) {
    j["sail"]["scanner_estimate"] = {{"position", vec(e->position)},
                                     {"sigma_m", vec(e->sigma_m)},
                                     {"mirror_ambiguous", e->mirror_ambiguous},
                                     {"beam_solid_angle_sr", e->beam_solid_angle_sr}};
  } else {
    j["sail"]["scanner_estimate"] = nullptr;
  }
  // How far the edges were moved out for the scanner's beam footprint (0: not).
  j["sail"]["beam_footprint_m"] = o.footprint_reach_m;
  // 1σ: a corner's as the distance it may lie off, the rest in their own units.
  j["sail"]["uncertainty"] = std::move(sail_sigma);
  nlohmann::json sections = nlohmann::json::array();
  for (const Section& s : a.sections.sections) sections.push_back(sectionToJson(s));
  j["sections"] = std::move(sections);
  j["unmeasured_sections"] = unmeasuredSectionsToJson(a.sections.unmeasured);
  const LuffCurve& l = a.luff;
  j["luff"] = {{"luff_chord_m", l.luff_chord_m},
               {"lufa_sag_m", l.lufa_sag_m},
               {"lufa_sag_pct", l.lufa_sag_pct},
               {"lufa_position_pct", l.lufa_position_pct},
               {"lusw_sag_m", l.lusw_sag_m},
               {"lusw_sag_pct", l.lusw_sag_pct},
               {"lusw_position_pct", l.lusw_position_pct},
               {"uncertainty",
                {{"luff_chord_m", l.uncertainty.luff_chord_m},
                 {"lufa_sag_m", l.uncertainty.lufa_sag_m},
                 {"lufa_sag_pct", l.uncertainty.lufa_sag_pct},
                 {"lufa_position_pct", l.uncertainty.lufa_position_pct},
                 {"lusw_sag_m", l.uncertainty.lusw_sag_m},
                 {"lusw_sag_pct", l.uncertainty.lusw_sag_pct},
                 {"lusw_position_pct", l.uncertainty.lusw_position_pct}}}};
  nlohmann::json stages = nlohmann::json::array();
  for (const StageReport& s : a.stages)
    stages.push_back({{"name", s.name},
                      {"points_in", s.points_in},
                      {"points_out", s.points_out},
                      {"seconds", s.seconds},
                      {"warnings", s.warnings}});
  nlohmann::json clusters = nlohmann::json::array();
  for (const ClusterInfo& c : a.clusters)
    clusters.push_back({{"points", c.points},
                        {"extent_m", c.extent_m},
                        {"width_m", c.width_m},
                        {"plane_rms_m", c.plane_rms_m},
                        {"bend_rms_m", c.bend_rms_m},
                        {"rough_rms_m", c.rough_rms_m},
                        {"tilt_from_vertical_deg", c.tilt_from_vertical_deg},
                        {"sail_like", c.sail_like},
                        {"reason", c.reason}});
  nlohmann::json spars = nlohmann::json::array();
  for (const SparFit& f : a.spars) {
    const Vec3 top = f.spar.base + f.spar.length_m * f.spar.axis;
    spars.push_back({{"base", {f.spar.base.x(), f.spar.base.y(), f.spar.base.z()}},
                     {"top", {top.x(), top.y(), top.z()}},
                     {"radius_m", f.spar.radius_m},
                     {"support", f.support},
                     {"rms_m", f.rms_m}});
  }
  const Smoothing& sm = a.smoothing_stats;
  j["diagnostics"] = {{"points_in", a.points_in},
                      {"sail_points", a.sail_points},
                      {"working_points", a.working_points},
                      {"working_voxel_m", a.working_voxel_m},
                      {"mesh_vertices", a.mesh.vertices.size()},
                      {"mesh_triangles", a.mesh.triangles.size()},
                      {"stages", stages},
                      {"clusters", clusters},
                      {"spars", spars},
                      {"smoothing", {{"good", sm.good},
                                     {"fair", sm.fair},
                                     {"bad", sm.bad},
                                     {"rms_displacement_m", sm.rms_displacement_m},
                                     {"max_displacement_m", sm.max_displacement_m},
                                     {"k_used", sm.k_used},
                                     {"measured_noise_m", sm.measured_noise_m}}},
                      {"warnings", a.warnings}};
  return j;
}

nlohmann::json sectionDeltasToJson(const std::vector<SectionDelta>& deltas) {
  nlohmann::json out = nlohmann::json::array();
  for (const SectionDelta& d : deltas)
    out.push_back({{"fraction", d.fraction},
                   {"design", sectionParametersToJson(d.design)},
                   {"flying", sectionParametersToJson(d.flying)},
                   {"delta", sectionParametersToJson(d.delta)}});
  return out;
}

}  // namespace sailshape
