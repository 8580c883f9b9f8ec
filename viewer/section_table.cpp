#include "viewer/section_table.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sailshape::viewer {

const std::vector<SectionField>& allFields() {
  static const std::vector<SectionField> fields = {SectionField::Chord,    SectionField::Camber, SectionField::Draft,
                                                   SectionField::Twist,    SectionField::TwistRel,
                                                   SectionField::Entry,    SectionField::Exit};
  return fields;
}

const FieldInfo& fieldInfo(SectionField field) {
  static const FieldInfo info[] = {
      {"chord", "m", "%.2f"},     {"camber", "%", "%.1f"},  {"draft", "%", "%.0f"}, {"twist", "°", "%.1f"},
      {"twist rel.", "°", "%.1f"}, {"entry", "°", "%.1f"}, {"exit", "°", "%.1f"}};
  return info[static_cast<int>(field)];
}

double fieldValue(const SectionParameters& p, SectionField field) {
  switch (field) {
    case SectionField::Chord: return p.chord_m;
    case SectionField::Camber: return p.camber_pct;
    case SectionField::Draft: return p.draft_pct;
    case SectionField::Twist: return p.twist_deg;
    case SectionField::TwistRel: return p.twist_rel_deg;
    case SectionField::Entry: return p.entry_deg;
    case SectionField::Exit: return p.exit_deg;
  }
  return std::nan("");
}

std::vector<SectionRow> sectionRows(const SectionAnalysis& flying, const std::vector<SectionDelta>& deltas) {
  std::vector<SectionRow> rows;
  for (const Section& s : flying.sections) {
    SectionRow r;
    r.fraction = s.fraction;
    r.height_m = s.luff_point.z();
    r.flying = s.value;
    r.uncertainty = s.uncertainty;
    for (const SectionDelta& d : deltas)
      if (std::abs(d.fraction - s.fraction) <= 1e-6) {
        r.design = d.design;
        r.delta = d.delta;
        // twist_rel as the comparison took it (from the lowest section both sides
        // measured), so that flying − design is the Δ shown beside them.
        r.flying.twist_rel_deg = d.flying.twist_rel_deg;
      }
    rows.push_back(r);
  }
  return rows;
}

std::vector<double> sectionColumns(const std::vector<const SectionAnalysis*>& steps) {
  std::vector<double> all;
  for (const SectionAnalysis* a : steps) {
    for (const Section& s : a->sections) all.push_back(s.fraction);
    for (const UnmeasuredSection& u : a->unmeasured) all.push_back(u.fraction);
  }
  std::sort(all.begin(), all.end());
  std::vector<double> columns;
  for (double f : all)
    if (columns.empty() || f - columns.back() >= 0.02) columns.push_back(f);
  return columns;
}

PlotSeries parameterVsHeight(const SectionAnalysis& sections, SectionField field, std::string label) {
  std::vector<const Section*> order;
  for (const Section& s : sections.sections) order.push_back(&s);
  std::sort(order.begin(), order.end(), [](const Section* a, const Section* b) { return a->luff_point.z() < b->luff_point.z(); });
  PlotSeries out;
  out.label = std::move(label);
  for (const Section* s : order) {
    out.value.push_back(fieldValue(s->value, field));
    out.height_m.push_back(s->luff_point.z());
  }
  return out;
}

AxisRange plotRange(const std::vector<PlotSeries>& series, bool values) {
  double lo = INFINITY, hi = -INFINITY;
  for (const PlotSeries& s : series)
    for (double v : values ? s.value : s.height_m)
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  if (!std::isfinite(lo)) return {};
  if (hi - lo < 1e-12) return {lo - 1, hi + 1};
  const double pad = 0.08 * (hi - lo);
  return {lo - pad, hi + pad};
}

}  // namespace sailshape::viewer
