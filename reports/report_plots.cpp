// The designer's and crew's plots: camber, draft and twist up the sail, and
// the section shapes, flying over design.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "reports/report_layout.hpp"
#include "reports/report_summary.hpp"

namespace sailshape::layout {
namespace {

// A section curve in its own chord frame, divided by the chord: x from luff (0)
// to leech (1), y the depth to the side the curve bulges to.
std::vector<std::pair<double, double>> chordProfile(const std::vector<Vec3>& curve) {
  std::vector<std::pair<double, double>> out;
  if (curve.size() < 3) return out;
  const Vec3 L = curve.front(), R = curve.back();
  const double chord = (R - L).norm();
  if (chord <= 0) return out;
  const Vec3 c = (R - L) / chord;
  Vec3 deepest = Vec3::Zero();
  for (const Vec3& p : curve) {
    const Vec3 off = (p - L) - (p - L).dot(c) * c;
    if (off.norm() > deepest.norm()) deepest = off;
  }
  if (deepest.norm() <= 0) return out;
  const Vec3 y = deepest.normalized();
  for (const Vec3& p : curve) out.emplace_back((p - L).dot(c) / chord, (p - L).dot(y) / chord);
  return out;
}


// A parameter against height: x the value, y the height fraction (up the page).
void profilePlot(PdfDocument& pdf, float x0, float y0, float w, float h, const std::string& title,
                 const std::vector<Series>& series, const char* tick_format) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i])) continue;
      const double u = std::isfinite(s.sigma[i]) ? s.sigma[i] : 0.0;
      lo = std::min(lo, s.x[i] - u);
      hi = std::max(hi, s.x[i] + u);
    }
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  const double pad = std::max(0.08 * (hi - lo), 0.5);
  lo -= pad;
  hi += pad;
  // The height axis spans the measured heights (sections at 25–75 % fill the plot,
  // not its middle half), labelled at each section's height when there are few.
  std::set<double> heights;
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i])) heights.insert(std::round(1000 * s.y[i]) / 1000);
  if (heights.empty()) heights = {0.0, 1.0};
  const double f_pad = std::max(0.1 * (*heights.rbegin() - *heights.begin()), 0.05);
  const double f_lo = std::max(0.0, *heights.begin() - f_pad), f_hi = std::min(1.0, *heights.rbegin() + f_pad);
  std::vector<double> height_ticks;
  if (heights.size() <= 9) {
    height_ticks.assign(heights.begin(), heights.end());
  } else {
    axisTicks(100 * f_lo, 100 * f_hi, height_ticks);
    for (double& t : height_ticks) t /= 100;
  }
  const float px = x0 + 30, pw = w - 38, py = y0 + 20, ph = h - 50;
  pdf.text(x0 + w / 2, y0 + 10, title, 10, true, kNavy, Align::Centre);
  auto X = [&](double v) { return float(px + (v - lo) / (hi - lo) * pw); };
  auto Y = [&](double f) { return float(py + ph - (f - f_lo) / (f_hi - f_lo) * ph); };
  for (double f : height_ticks) {
    pdf.line(px, Y(f), px + pw, Y(f), 0.4f, kLightGrey);
    pdf.text(px - 4, Y(f) + 3, fmt("%.0f", 100 * f), 7, false, kGrey, Align::Right);
  }
  std::vector<double> ticks;
  axisTicks(lo, hi, ticks);
  for (double t : ticks) {
    pdf.line(X(t), py, X(t), py + ph, 0.4f, kLightGrey);
    pdf.text(X(t), py + ph + 10, signedFmt(tick_format, t), 7, false, kGrey, Align::Centre);
  }
  pdf.frame(px, py, pw, ph, 0.6f, kRule);
  for (const auto& s : series) {
    std::vector<std::pair<float, float>> line;
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i])) continue;
      line.emplace_back(X(s.x[i]), Y(s.y[i]));
      if (std::isfinite(s.sigma[i]) && s.sigma[i] > 0) {
        pdf.line(X(s.x[i] - s.sigma[i]), Y(s.y[i]), X(s.x[i] + s.sigma[i]), Y(s.y[i]), 0.8f, s.colour);
        pdf.line(X(s.x[i] - s.sigma[i]), Y(s.y[i]) - 2, X(s.x[i] - s.sigma[i]), Y(s.y[i]) + 2, 0.8f, s.colour);
        pdf.line(X(s.x[i] + s.sigma[i]), Y(s.y[i]) - 2, X(s.x[i] + s.sigma[i]), Y(s.y[i]) + 2, 0.8f, s.colour);
      }
    }
    pdf.polyline(line, 1.4f, s.colour, s.dashed);
    for (const auto& [lx, ly] : line) pdf.disc(lx, ly, 1.8f, s.colour);
  }
}

std::vector<Series> parameterSeries(const TrimReportData& r, double SectionParameters::*field, bool with_design) {
  std::vector<Series> out;
  const auto& d = r.data;
  if (with_design) {
    Series s{"design", kDesignBlue, true, {}, {}, {}};
    for (const Section& ds : r.design_sections.sections) {
      s.y.push_back(ds.fraction);
      s.x.push_back(ds.value.*field);
      s.sigma.push_back(kNaN);
    }
    out.push_back(std::move(s));
  }
  for (size_t i = 0; i < d.steps.size(); ++i) {
    Series s{d.steps.size() == 1 ? "flying" : stepLabel(d, d.steps[i]), stepColour(i, d.steps.size()), false, {}, {}, {}};
    for (const ReportSection& fs : d.steps[i].sections) {
      s.y.push_back(fs.fraction);
      s.x.push_back(fs.value.*field);
      s.sigma.push_back(fs.uncertainty.*field);
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace

void plotsPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r, bool crew) {
  float y = pages.start("Camber, draft and twist up the sail");
  const float w = pdf.pageWidth();
  const std::vector<Series> camber = parameterSeries(r, &SectionParameters::camber_pct, true);
  legendRow(pdf, kMargin, y + 4, camber);
  y += 20;
  const float pw = (w - 2 * kMargin) / 3, ph = 430;
  profilePlot(pdf, kMargin, y, pw, ph, "Camber, % of chord", camber, "%.0f");
  profilePlot(pdf, kMargin + pw, y, pw, ph, "Draft, % of chord from luff",
              parameterSeries(r, &SectionParameters::draft_pct, true), "%.0f");
  profilePlot(pdf, kMargin + 2 * pw, y, pw, ph, "Twist, ° to centreline",
              parameterSeries(r, &SectionParameters::twist_deg, true), "%.0f");
  y += ph + 8;
  pdf.text(kMargin, y, "Vertical axis: height, % of luff. Bars: ±1σ of the measurement.", 8.5f, false, kGrey);
  y += 20;
  const std::string text =
      crew ? "Deeper than the blue line means more power than designed; draft to the right means the deepest point "
             "has moved aft; twist to the right means the sail is more open (twisted off) than designed."
           : "Design values from the design surface analysed at the flying heights (dashed); flying values as stored "
             "with their 1σ. Twist is the chord's angle to the centreline in the horizontal plane (SPEC §5).";
  pdf.paragraph(kMargin, y, w - 2 * kMargin, text, 9.5f);
}

void curvesPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r) {
  float y = pages.start("Section shapes, flying over design");
  const float w = pdf.pageWidth();
  std::vector<Series> legend = {{"design", kDesignBlue, true, {}, {}, {}}};
  const auto& d = r.data;
  for (size_t i = 0; i < d.steps.size(); ++i)
    legend.push_back({d.steps.size() == 1 ? "flying" : stepLabel(d, d.steps[i]), stepColour(i, d.steps.size()), false,
                      {}, {}, {}});
  legendRow(pdf, kMargin, y + 4, legend);
  y += 18;
  const auto& fractions = r.design_sections.sections;
  const size_t n = fractions.size();
  const int cols = n > 4 ? 2 : 1;
  const int rows = static_cast<int>((n + cols - 1) / cols);
  const float cw = (w - 2 * kMargin - (cols - 1) * 14) / cols;
  const float ch = std::min(150.f, (pdf.pageHeight() - y - 50) / rows);

  // Every profile of the page, in chord units, luff to leech.
  struct Drawn {
    std::vector<std::pair<double, double>> profile;
    Rgb colour;
    bool dashed;
  };
  std::vector<std::vector<Drawn>> panels(n);
  double v_hi = 0, v_lo = 0;  // deepest to the bulging side, and to the other (an S-shaped section)
  for (size_t idx = 0; idx < n; ++idx) {
    const double f = fractions[idx].fraction;
    panels[idx].push_back({chordProfile(fractions[idx].curve), kDesignBlue, true});
    for (size_t i = 0; i < d.steps.size(); ++i)
      for (const ReportSection& s : d.steps[i].sections)
        if (std::abs(s.fraction - f) < 1e-6) panels[idx].push_back({chordProfile(s.curve), stepColour(i, d.steps.size()), false});
    for (const Drawn& dr : panels[idx])
      for (const auto& [u, v] : dr.profile) v_hi = std::max(v_hi, v), v_lo = std::min(v_lo, v);
  }
  // One scale for the page, chosen so the deepest section stays inside its panel
  // (below its title, above its luff/leech labels): depth exaggerated 2× where it
  // fits, less where not, and the whole drawing narrowed when even true scale does not.
  const float room = ch - 34;  // points of depth per panel
  float chord_pt = cw - 8, exaggerate = 2.0f;
  const double depth = std::max(v_hi - v_lo, 1e-3);
  for (float e : {2.0f, 1.5f, 1.0f}) {
    exaggerate = e;
    if (depth * e * chord_pt <= room) break;
  }
  if (depth * exaggerate * chord_pt > room) chord_pt = float(room / depth);
  pdf.text(w - kMargin, y - 14,
           exaggerate == 1.0f ? "depth drawn to true scale" : fmt("depth drawn %g× its true scale", exaggerate), 8.5f,
           false, kGrey, Align::Right);

  for (size_t k = 0; k < n; ++k) {
    const size_t idx = n - 1 - k;  // head first
    const double f = fractions[idx].fraction;
    const float x0 = kMargin + (k % cols) * (cw + 14), y0 = y + (k / cols) * ch;
    pdf.text(x0, y0 + 10, fmt("%.0f %% height", 100 * f) + " · " + heightName(f), 9, true, kNavy);
    const float px = x0 + 4 + (cw - 8 - chord_pt) / 2;  // centred when narrowed
    const float base = y0 + 18 + float(v_hi * exaggerate * chord_pt);
    const float below = base + float(-v_lo * exaggerate * chord_pt);
    pdf.line(px, base, px + chord_pt, base, 0.5f, kRule, true);  // the chord
    for (const Drawn& dr : panels[idx]) {
      std::vector<std::pair<float, float>> line;
      for (const auto& [u, v] : dr.profile) line.emplace_back(px + u * chord_pt, base - exaggerate * v * chord_pt);
      pdf.polyline(line, 1.3f, dr.colour, dr.dashed);
    }
    pdf.text(px, below + 10, "luff", 7, false, kGrey);
    pdf.text(px + chord_pt, below + 10, "leech", 7, false, kGrey, Align::Right);
  }
}

}  // namespace sailshape::layout
