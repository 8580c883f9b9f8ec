#pragma once
// The report's page furniture shared by its page writers (trim_report.cpp,
// report_plots.cpp, changes_page.cpp): colours, number formats, the header and
// footer of each page, and the plot legend. Internal to reports/.
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "reports/pdf_document.hpp"
#include "reports/trim_report.hpp"

namespace sailshape::layout {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr float kMargin = 42;
inline const Rgb kBlack{0, 0, 0}, kGrey{0.45, 0.45, 0.45}, kLightGrey{0.88, 0.88, 0.88}, kRule{0.75, 0.75, 0.75};
inline const Rgb kNavy{0.06, 0.16, 0.33}, kBand{0.93, 0.95, 0.98};

// printf of one number; "–" for NaN.
std::string fmt(const char* f, double v);
// "v ± u" with both in format f; "–" for NaN.
std::string fmtPm(const char* f, double v, double u);
// With a '+' sign and a real minus sign; no sign on zero.
std::string signedFmt(const char* f, double v);
// Step colours for a test's overlays; the design is always blue.
Rgb stepColour(size_t i, size_t n);
// A round number at or above v for axis ranges and the colour map: 1, 2, 2.5, 5 × 10^k.
double niceCeil(double v);
// Round-valued ticks from lo to hi, about five.
void axisTicks(double lo, double hi, std::vector<double>& ticks);

struct Series {
  std::string label;
  Rgb colour;
  bool dashed = false;
  std::vector<double> y, x, sigma;  // y: height fraction; x: value; sigma: 1σ of x (NaN: none)
};
void legendRow(PdfDocument& pdf, float x, float y, const std::vector<Series>& series);

class Pages {
 public:
  Pages(PdfDocument& pdf, const ReportData& d) : pdf_(pdf), d_(d) {}
  // A new page with the header band; returns the y where content starts.
  float start(const std::string& title, bool landscape = false);

 private:
  PdfDocument& pdf_;
  const ReportData& d_;
};

std::string stepLabel(const ReportData& d, const ReportStep& s);
std::string conditions(const ReportStep& s);

// The pages written outside trim_report.cpp.
void plotsPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r, bool crew);
void curvesPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r);
void changesPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r, bool crew);

}  // namespace sailshape::layout
