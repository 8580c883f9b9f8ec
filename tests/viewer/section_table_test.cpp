#include <gtest/gtest.h>

#include <cmath>

#include "viewer/section_table.hpp"

namespace sailshape::viewer {
namespace {

Section section(double f, double z, double camber) {
  Section s;
  s.fraction = f;
  s.luff_point = Vec3(0, 0, z);
  s.value.camber_pct = camber;
  s.value.draft_pct = 45;
  s.value.twist_deg = 10 + z;
  s.uncertainty.camber_pct = 0.2;
  return s;
}

TEST(SectionTable, RowsPairFlyingWithDesignByFraction) {
  SectionAnalysis flying;
  flying.sections = {section(0.25, 3.0, 12.0), section(0.5, 6.0, 13.0), section(0.75, 9.0, 11.0)};
  SectionDelta d;
  d.fraction = 0.5;
  d.design.camber_pct = 11.0;
  d.flying.camber_pct = 13.0;
  d.delta.camber_pct = 2.0;
  const auto rows = sectionRows(flying, {d});
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_FALSE(rows[0].design.has_value());
  ASSERT_TRUE(rows[1].design.has_value());
  EXPECT_DOUBLE_EQ(rows[1].design->camber_pct, 11.0);
  EXPECT_DOUBLE_EQ(rows[1].delta->camber_pct, 2.0);
  EXPECT_DOUBLE_EQ(rows[1].height_m, 6.0);
  EXPECT_DOUBLE_EQ(rows[2].uncertainty.camber_pct, 0.2);
  EXPECT_TRUE(sectionRows(SectionAnalysis{}).empty());
}

TEST(SectionTable, TrimComparisonColumnsCoverEveryStepsSections) {
  // The loaded step left 0.5 unmeasured; an overlaid step measured it, and 0.76 beside 0.75.
  SectionAnalysis loaded, overlay;
  loaded.sections = {section(0.25, 3.0, 12.0), section(0.75, 9.0, 11.0)};
  loaded.unmeasured = {{0.5, "crosses a hole"}};
  overlay.sections = {section(0.5, 6.0, 13.0), section(0.76, 9.1, 11.5), section(0.9, 10.0, 9.0)};
  const std::vector<double> columns = sectionColumns({&loaded, &overlay});
  ASSERT_EQ(columns.size(), 4u);
  EXPECT_DOUBLE_EQ(columns[0], 0.25);
  EXPECT_DOUBLE_EQ(columns[1], 0.5);
  EXPECT_DOUBLE_EQ(columns[2], 0.75);
  EXPECT_DOUBLE_EQ(columns[3], 0.9);
  EXPECT_TRUE(sectionColumns({}).empty());
}

TEST(SectionTable, SeriesAreSortedByHeight) {
  SectionAnalysis a;
  a.sections = {section(0.75, 9.0, 11.0), section(0.25, 3.0, 12.0)};
  const PlotSeries s = parameterVsHeight(a, SectionField::Twist, "flying");
  EXPECT_EQ(s.label, "flying");
  EXPECT_EQ(s.height_m, (std::vector<double>{3.0, 9.0}));
  EXPECT_EQ(s.value, (std::vector<double>{13.0, 19.0}));
  EXPECT_DOUBLE_EQ(fieldValue(a.sections[0].value, SectionField::Camber), 11.0);
  EXPECT_EQ(std::string(fieldInfo(SectionField::Draft).unit), "%");
  EXPECT_EQ(allFields().size(), 7u);
}

TEST(SectionTable, PlotRangeCoversEveryFiniteValueWithPadding) {
  PlotSeries a{"a", {10.0, std::nan(""), 12.0}, {1.0, 2.0, 3.0}};
  PlotSeries b{"b", {14.0}, {5.0}};
  const AxisRange v = plotRange({a, b}, true);
  EXPECT_DOUBLE_EQ(v.lo, 10.0 - 0.08 * 4.0);
  EXPECT_DOUBLE_EQ(v.hi, 14.0 + 0.08 * 4.0);
  const AxisRange h = plotRange({a, b}, false);
  EXPECT_DOUBLE_EQ(h.lo, 1.0 - 0.08 * 4.0);
  const AxisRange single = plotRange({b}, true);
  EXPECT_DOUBLE_EQ(single.lo, 13.0);
  EXPECT_DOUBLE_EQ(single.hi, 15.0);
  const AxisRange none = plotRange({}, true);
  EXPECT_DOUBLE_EQ(none.lo, 0.0);
  EXPECT_DOUBLE_EQ(none.hi, 1.0);
}

}  // namespace
}  // namespace sailshape::viewer
