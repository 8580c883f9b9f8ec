#pragma once
// The section table (design, flying, difference) and the parameter-vs-height
// plot series, as plain data the panels draw.
#include <optional>
#include <string>
#include <vector>

#include "analysis/design/design_compare.hpp"
#include "analysis/sections/sections.hpp"

namespace sailshape::viewer {

enum class SectionField { Chord, Camber, Draft, Twist, TwistRel, Entry, Exit };

struct FieldInfo {
  const char* name;    // "camber"
  const char* unit;    // "%"
  const char* format;  // printf format of one value
};
const FieldInfo& fieldInfo(SectionField field);
const std::vector<SectionField>& allFields();
double fieldValue(const SectionParameters& p, SectionField field);

struct SectionRow {
  double fraction = 0;
  double height_m = 0;                       // z of the section's luff point, boat frame
  SectionParameters flying, uncertainty;
  std::optional<SectionParameters> design;   // when the design was cut at this fraction
  std::optional<SectionParameters> delta;    // flying − design
};

// One row per flying section; design and delta from `deltas` matched by fraction (±1e-6).
std::vector<SectionRow> sectionRows(const SectionAnalysis& flying, const std::vector<SectionDelta>& deltas = {});

// The trim comparison's columns: every section fraction any of `steps` measured or
// left unmeasured, ascending, fractions closer than 0.02 taken as one (the first).
std::vector<double> sectionColumns(const std::vector<const SectionAnalysis*>& steps);

struct PlotSeries {
  std::string label;
  std::vector<double> value;     // the parameter, in its unit (NaN: not measurable, skipped)
  std::vector<double> height_m;  // z of each section's luff point
};

// `field` against height for every section (sorted by height).
PlotSeries parameterVsHeight(const SectionAnalysis& sections, SectionField field, std::string label);

struct AxisRange {
  double lo = 0, hi = 1;
};
// Range of the values (value axis when `values`, else heights) of all series,
// padded by 8 % each side; [0, 1] when there is no finite value; a single value
// gets ±1 unit so the axis has a width.
AxisRange plotRange(const std::vector<PlotSeries>& series, bool values);

}  // namespace sailshape::viewer
