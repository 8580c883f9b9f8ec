// `--state FILE`: what the panels show, as JSON, so tests (and scripts) read the
// numbers a person reads: the scan in the 3D view and its captions, the design
// against flying statistics in millimetres, the Sections tab's table, the
// browser's labels, the messages, and any panel whose content runs past its edge.
// Values are SI in the JSON's own units (keys end in _mm, _m, _pct, _deg); null
// where the panel shows "—".
#include <cmath>

#include "viewer/app.hpp"
#include "viewer/widgets.hpp"

namespace sailshape::viewer {
namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// The JSON key of a table row: its name and unit, as the SI suffix (SPEC §2).
std::string fieldKey(SectionField f) {
  switch (f) {
    case SectionField::Chord: return "chord_m";
    case SectionField::Camber: return "camber_pct";
    case SectionField::Draft: return "draft_pct";
    case SectionField::Twist: return "twist_deg";
    case SectionField::TwistRel: return "twist_rel_deg";
    case SectionField::Entry: return "entry_deg";
    case SectionField::Exit: return "exit_deg";
  }
  return "";
}

nlohmann::json sectionTable(const ScanScene& s) {
  nlohmann::json out = nlohmann::json::array();
  const SectionField fields[] = {SectionField::Camber, SectionField::Draft, SectionField::Twist,
                                 SectionField::Entry,  SectionField::Exit,  SectionField::Chord};
  for (const SectionRow& r : sectionRows(s.sections, s.deltas)) {
    nlohmann::json row = {{"fraction", r.fraction}, {"height_m", number(r.height_m)}};
    for (SectionField f : fields) {
      row[fieldKey(f)] = {{"design", r.design ? number(fieldValue(*r.design, f)) : nlohmann::json()},
                          {"flying", number(fieldValue(r.flying, f))},
                          {"delta", r.delta ? number(fieldValue(*r.delta, f)) : nlohmann::json()},
                          {"sigma", number(fieldValue(r.uncertainty, f))}};
    }
    out.push_back(row);
  }
  return out;
}

nlohmann::json browserLabels(const CatalogTree& tree) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : tree.campaigns) {
    out.push_back(c.name);
    for (const auto& t : c.tests) {
      out.push_back(t.label());
      for (const auto& s : t.steps) {
        out.push_back(s.label());
        for (const auto& scan : s.scans) out.push_back("scan " + std::to_string(scan.scan_id));
      }
    }
  }
  return out;
}

}  // namespace

nlohmann::json App::state() const {
  nlohmann::json j;
  j["database"] = {{"path", database_.path}, {"open", database_.db.has_value()}, {"error", database_.error}};
  j["browser"] = {{"scan_count", browser_.tree.scan_count}, {"labels", browserLabels(browser_.tree)}};
  j["scan"] = nullptr;
  j["deviation_mm"] = nullptr;
  j["sections"] = nlohmann::json::array();
  if (load_.scene) {
    const ScanScene& s = *load_.scene;
    const ScanRecord& r = s.record;
    j["scan"] = {{"scan_id", r.scan_id},
                 {"campaign", r.campaign},
                 {"test", r.test},
                 {"step", r.step},
                 {"sail", r.sail},
                 {"awa_deg", r.awa_deg ? nlohmann::json(*r.awa_deg) : nlohmann::json()},
                 {"live_sweep", live_.shown_sweep},
                 {"title", viewTitle()},
                 {"has_design", !s.design.empty()},
                 {"has_surface", !s.surface.empty()},
                 {"analysis_error", s.analysis_error}};
    if (s.deviation) {
      const DistanceStats& d = *s.deviation;
      j["deviation_mm"] = {{"points", d.count},           {"mean", 1000 * d.mean_m}, {"rms", 1000 * d.rms_m},
                           {"p5", 1000 * d.p5_m},         {"p50", 1000 * d.p50_m},   {"p95", 1000 * d.p95_m},
                           {"max_abs", 1000 * d.max_abs_m}, {"caption", deviationCaption(d)},
                           {"summary", deviationSummary(d)}};
    }
    // Drawn in red under the deviation in the Sections tab when not empty.
    j["design_mismatch"] = s.design_mismatch.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.design_mismatch);
    j["sections"] = sectionTable(s);
    j["unmeasured_sections"] = nlohmann::json::array();
    for (const UnmeasuredSection& u : s.sections.unmeasured)
      j["unmeasured_sections"].push_back({{"fraction", u.fraction}, {"reason", u.reason}});
    j["warnings"] = s.warnings;
    // The design fitted to the scan: how much of it samples held, and its move along the normal.
    j["fitted"] = nullptr;
    if (s.fitted) {
      size_t inferred = 0;
      for (char supported : s.fitted->supported) inferred += supported ? 0 : 1;
      j["fitted"] = {{"vertices", s.fitted->fitted.vertices.size()},
                     {"inferred_vertices", inferred},
                     {"coverage", s.fitted->coverage},
                     {"rms_mm", 1000 * s.fitted->rms_m}};
    }
  }
  if (pick_.info)
    j["pick"] = {{"what", pick_.info->what},
                 {"point_m", {pick_.info->point.x(), pick_.info->point.y(), pick_.info->point.z()}},
                 {"deviation_mm", pick_.info->deviation_m ? nlohmann::json(1000 * *pick_.info->deviation_m)
                                                          : nlohmann::json()}};
  const LiveStatus live = live_.mode.status();
  j["live"] = {{"running", live.running}, {"swept", live.swept}, {"analysed", live.analysed}, {"failed", live.failed}};
  j["messages"] = log_.lines;
  // The last frame's windows whose items reach past their right edge (px): text cut off
  // at a panel's edge, which the screenshot shows and no other key tells.
  j["overflow_px"] = nlohmann::json::object();
  for (const auto& [window, px] : overflowingWindows()) j["overflow_px"][window] = px;
  return j;
}

}  // namespace sailshape::viewer
