#include "reports/trim_report.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <limits>
#include <set>

#include "analysis/core/errors.hpp"
#include "database/schema.hpp"
#include "reports/private_display.hpp"

namespace sailshape {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr float kMargin = 42;
const Rgb kBlack{0, 0, 0}, kGrey{0.45, 0.45, 0.45}, kLightGrey{0.88, 0.88, 0.88}, kRule{0.75, 0.75, 0.75};
const Rgb kNavy{0.06, 0.16, 0.33}, kBand{0.93, 0.95, 0.98};

std::string fmt(const char* f, double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}
std::string fmtPm(const char* f, double v, double u) {
  if (!std::isfinite(v)) return "–";
  return fmt(f, v) + (std::isfinite(u) ? " ± " + fmt(f, std::abs(u)) : "");
}
std::string signedFmt(const char* f, double v) {  // '+' sign, and a real minus sign
  std::string s = fmt(f, v);
  if (s.find_first_of("123456789") == std::string::npos && (s[0] == '-' || s[0] == '+')) s = s.substr(1);
  if (!s.empty() && s[0] == '-') s = "−" + s.substr(1);
  return s;
}

// Step colours for a test's overlays; the design is always blue.
Rgb stepColour(size_t i, size_t n) {
  static const Rgb palette[] = {{0.85, 0.12, 0.10}, {0.95, 0.55, 0.05}, {0.55, 0.15, 0.65},
                                {0.10, 0.60, 0.30}, {0.45, 0.30, 0.15}, {0.90, 0.30, 0.60}};
  if (n == 1) return kFlyingRed;
  return palette[i % (sizeof(palette) / sizeof(palette[0]))];
}

// A round number at or above v for axis ranges and the colour map: 1, 2, 2.5, 5 × 10^k.
double niceCeil(double v) {
  if (!(v > 0)) return 1;
  const double e = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * e >= v * (1 - 1e-9)) return m * e;
  return 10 * e;
}

std::vector<Vec3> resampleByArc(const std::vector<Vec3>& curve, int n) {
  std::vector<double> s(curve.size(), 0.0);
  for (size_t i = 1; i < curve.size(); ++i) s[i] = s[i - 1] + (curve[i] - curve[i - 1]).norm();
  std::vector<Vec3> out;
  size_t j = 1;
  for (int k = 0; k < n; ++k) {
    const double target = s.back() * k / (n - 1);
    while (j + 1 < curve.size() && s[j] < target) ++j;
    const double span = s[j] - s[j - 1];
    const double t = span > 0 ? std::clamp((target - s[j - 1]) / span, 0.0, 1.0) : 0.0;
    out.push_back(curve[j - 1] + t * (curve[j] - curve[j - 1]));
  }
  return out;
}

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

struct Series {
  std::string label;
  Rgb colour;
  bool dashed = false;
  std::vector<double> y, x, sigma;  // y: height fraction; x: value; sigma: 1σ of x (NaN: none)
};

void axisTicks(double lo, double hi, std::vector<double>& ticks) {
  const double step = niceCeil((hi - lo) / 5);
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) ticks.push_back(t);
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
  const float px = x0 + 30, pw = w - 38, py = y0 + 20, ph = h - 50;
  pdf.text(x0 + w / 2, y0 + 10, title, 10, true, kNavy, Align::Centre);
  auto X = [&](double v) { return float(px + (v - lo) / (hi - lo) * pw); };
  auto Y = [&](double f) { return float(py + ph - f * ph); };
  for (double f = 0; f <= 1.0001; f += 0.25) {
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

void legendRow(PdfDocument& pdf, float x, float y, const std::vector<Series>& series) {
  for (const auto& s : series) {
    pdf.line(x, y - 3, x + 18, y - 3, 1.6f, s.colour, s.dashed);
    pdf.text(x + 22, y, s.label, 8.5f);
    x += 22 + pdf.textWidth(s.label, 8.5f) + 16;
  }
}

class Pages {
 public:
  Pages(PdfDocument& pdf, const ReportData& d) : pdf_(pdf), d_(d) {}
  // A new page with the header band; returns the y where content starts.
  float start(const std::string& title, bool landscape = false) {
    pdf_.addPage(landscape);
    const float w = pdf_.pageWidth(), h = pdf_.pageHeight();
    pdf_.rect(0, 0, w, 34, kNavy);
    // The title shrinks (to 10 pt) to keep clear of the sail and boat on the right;
    // when it still does not fit, the sail and boat go up to the band's top line.
    const std::string who = d_.sail + (d_.boat.empty() ? "" : " · " + d_.boat);
    const float room = w - 2 * kMargin - pdf_.textWidth(who, 9) - 12;
    float size = 13;
    while (size > 10 && pdf_.textWidth(title, size, true) > room) size -= 0.5f;
    const bool beside = pdf_.textWidth(title, size, true) <= room;
    pdf_.text(kMargin, beside ? 22 : 27, title, size, true, {1, 1, 1});
    pdf_.text(w - kMargin, beside ? 22 : 11, who, beside ? 9 : 7.5f, false, {0.85, 0.9, 1}, Align::Right);
    pdf_.line(kMargin, h - 28, w - kMargin, h - 28, 0.4f, kRule);
    pdf_.text(kMargin, h - 16, "sailshape trim report · " + d_.campaign + (d_.test.empty() ? "" : " · test " + d_.test),
              7.5f, false, kGrey);
    pdf_.text(w - kMargin, h - 16, "page " + std::to_string(pdf_.pageCount()), 7.5f, false, kGrey, Align::Right);
    return 58;
  }

 private:
  PdfDocument& pdf_;
  const ReportData& d_;
};

std::string stepLabel(const ReportData& d, const ReportStep& s) {
  if (d.steps.size() == 1 && d.test.empty()) return "scan " + std::to_string(s.scan_id);
  return "step " + std::to_string(s.step_order);
}

std::string conditions(const ReportStep& s) {
  std::string out;
  if (s.awa_deg) out += "AWA " + fmt("%.1f°", *s.awa_deg);
  if (s.aws_m_s) out += (out.empty() ? "" : ", ") + std::string("AWS ") + fmt("%.1f m/s", *s.aws_m_s);
  return out.empty() ? "wind not recorded" : out;
}

std::string today() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(buf, sizeof(buf), "%Y-%m-%d", &tm);
  return buf;
}

// ---------------------------------------------------------------- pages

void coverPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r, bool crew) {
  const ReportData& d = r.data;
  float y = pages.start("Sail shape report");
  const float w = pdf.pageWidth();
  pdf.text(kMargin, y + 22, d.sail, 26, true, kNavy);
  std::string sub = d.sail_type.empty() ? "" : d.sail_type;
  if (!d.boat.empty()) sub += (sub.empty() ? "" : " · ") + d.boat + (d.boat_class.empty() ? "" : " (" + d.boat_class + ")");
  pdf.text(kMargin, y + 44, sub, 13, false, kGrey);
  y += 72;

  const ReportStep& first = d.steps.front();
  std::string date = first.scanned_at.empty() ? d.session_started : first.scanned_at;
  if (date.size() > 10 && date[10] == 'T') date = date.substr(0, 10) + " " + date.substr(11, 5);
  std::vector<std::pair<std::string, std::string>> rows = {
      {"Boat", d.boat.empty() ? "–" : d.boat + (d.boat_class.empty() ? "" : ", " + d.boat_class)},
      {"Sail", d.sail + (d.sail_type.empty() ? "" : ", " + d.sail_type) +
                   (d.size_variant.empty() ? "" : ", size " + d.size_variant)},
      {"Design", (d.designer.empty() ? std::string("designer not recorded") : d.designer) +
                     (d.version.empty() ? "" : ", version " + d.version)},
      {"Campaign", d.campaign + " (" + (d.campaign_kind == "wind_tunnel" ? "wind tunnel" : "full scale") + ")" +
                       (d.place.empty() ? "" : ", " + d.place)},
      {"Session", d.session},
      {"Date", date.empty() ? "not recorded" : date},
  };
  if (!d.test.empty())
    rows.push_back({"Test", d.test + " · " +
                                (d.steps.size() > 1 ? std::to_string(d.steps.size()) + " trim steps"
                                                    : "trim step " + std::to_string(d.steps.front().step_order))});
  for (const ReportStep& s : d.steps) {
    std::string forces;
    if (s.drive_n) forces += ", drive " + fmt("%.0f N", *s.drive_n);
    if (s.side_n) forces += ", side " + fmt("%.0f N", *s.side_n);
    rows.push_back({d.steps.size() == 1 ? "Conditions" : "Step " + std::to_string(s.step_order),
                    conditions(s) + forces + " (scan " + std::to_string(s.scan_id) + ")"});
  }
  for (const auto& [k, v] : rows) {
    pdf.text(kMargin, y, k, 10, true, kNavy);
    y = pdf.paragraph(kMargin + 90, y, w - 2 * kMargin - 90, v, 10) + 3;
  }

  y += 14;
  pdf.rect(kMargin, y, w - 2 * kMargin, 22, kBand);
  pdf.text(kMargin + 8, y + 15, crew ? "How the sail flew" : "Largest differences from the design", 12, true, kNavy);
  y += 40;
  const std::string which = d.steps.size() > 1 ? " (" + stepLabel(d, d.steps.back()) + ")" : "";
  // Sections the last step's analysis could not measure are named: "every section
  // flew within ..." must not hide them.
  std::vector<std::string> missing;
  for (const UnmeasuredSection& u : d.steps.back().unmeasured)
    missing.push_back(fmt("The %.0f %% section was not measured", 100 * u.fraction) + " (" + u.reason + ").");
  if (r.summary.within_design && missing.empty()) {
    y = pdf.paragraph(kMargin + 8, y, w - 2 * kMargin - 16,
                      "Every section flew within the report's thresholds of its design" + which + ".", 11);
  } else {
    std::vector<std::string> lines = r.summary.sentences;
    if (r.summary.within_design)
      lines.push_back("Every measured section flew within the report's thresholds of its design.");
    lines.insert(lines.end(), missing.begin(), missing.end());
    for (const std::string& s : lines) {
      pdf.disc(kMargin + 10, y - 4, 2, kFlyingRed);
      y = pdf.paragraph(kMargin + 20, y, w - 2 * kMargin - 28, s, 11) + 4;
    }
    if (!which.empty()) y = pdf.paragraph(kMargin + 20, y, w - 2 * kMargin - 28, "Shown for the last trim step" + which + ".", 9, false, kGrey);
  }
  const StepComparison& last = r.steps.back();
  y += 6;
  y = pdf.paragraph(kMargin + 8, y, w - 2 * kMargin - 16,
                    "Over the measured part of the sail the flying shape lies on average " +
                        signedFmt("%+.0f", 1000 * last.deviation.mean_m) + " mm from the design (positive: to leeward), " +
                        "and 90 % of it within " + signedFmt("%+.0f", 1000 * last.deviation.p5_m) + " … " +
                        signedFmt("%+.0f", 1000 * last.deviation.p95_m) + " mm.",
                    10, false, kGrey);

  y = std::max(y + 20, pdf.pageHeight() - 150);
  pdf.line(kMargin, y, w - kMargin, y, 0.4f, kRule);
  y += 16;
  pdf.text(kMargin, y, "Units", 9, true, kNavy);
  pdf.paragraph(kMargin + 50, y, w - 2 * kMargin - 50,
                "Lengths in metres, deviations in millimetres; camber and draft in % of the section's chord; twist, "
                "entry and exit angles in degrees; wind speed in m/s; forces in newtons, heel moment in N·m. "
                "Height is the section's fraction of luff and leech (0 % foot, 100 % head). ± is one standard "
                "deviation (1σ) of the measurement.",
                8.5f, false, kGrey);
  y += 56;
  pdf.text(kMargin, y, "Made", 9, true, kNavy);
  pdf.text(kMargin + 50, y, today() + " by sailshape for the " + std::string(crew ? "crew" : "designer") + ".", 8.5f,
           false, kGrey);
}

// Picture frames of the 3D page, in points; their aspect ratios are those of
// RenderParams' default picture sizes.
struct ViewLayout {
  float side_w = 190, astern_w = 90, row1_h = 330, gap = 20.5f, top_w = 250, top_h = 190;
};

void viewsPage(PdfDocument& pdf, Pages& pages, const ReportData& d, const ReportStep& step, const StepComparison& c,
               const SailViews& v, double range_m) {
  float y = pages.start("Shape in 3D · " + stepLabel(d, step) + " · " + conditions(step));
  const ViewLayout L;
  auto place = [&](const RgbImage& img, float x, float top, float w, float h, const std::string& caption) {
    pdf.image(img, x, top, w, h);
    pdf.frame(x, top, w, h, 0.5f, kRule);
    pdf.text(x + w / 2, top + h + 12, caption, 8.5f, false, kBlack, Align::Centre);
  };
  float x = kMargin;
  place(v.side, x, y, L.side_w, L.row1_h, "From the side (port), bow to the right");
  x += L.side_w + L.gap;
  place(v.astern, x, y, L.astern_w, L.row1_h, "From astern");
  x += L.astern_w + L.gap;
  place(v.deviation, x, y, L.side_w, L.row1_h, "Deviation from the design");
  y += L.row1_h + 34;
  place(v.top, kMargin, y, L.top_w, L.top_h, "From above, bow up");

  // Beside the top view: what the colours mean.
  const float lx = kMargin + L.top_w + 24, lw = pdf.pageWidth() - kMargin - lx;
  float ly = y + 10;
  pdf.text(lx, ly, "Shape views", 9.5f, true, kNavy);
  ly += 16;
  pdf.line(lx, ly - 3, lx + 18, ly - 3, 1.6f, kDesignBlue);
  pdf.text(lx + 24, ly, "design, as a grid", 8.5f);
  ly += 14;
  pdf.rect(lx, ly - 8, 18, 8, kFlyingRed);
  ly = pdf.paragraph(lx + 24, ly, lw - 24, "flying shape, lofted through the measured sections", 8.5f) + 14;
  pdf.text(lx, ly, "Deviation, mm", 9.5f, true, kNavy);
  ly += 10;
  const float bh = 10;
  const int n = 100;
  for (int i = 0; i < n; ++i) {
    const double t = -range_m + 2 * range_m * (i + 0.5) / n;
    pdf.rect(lx + lw * i / n, ly, lw / n + 0.3f, bh, deviationColour(t, range_m));
  }
  pdf.frame(lx, ly, lw, bh, 0.4f, kRule);
  for (int k = -2; k <= 2; ++k) {
    const float tx = lx + lw * (k + 2) / 4.0f;
    pdf.line(tx, ly + bh, tx, ly + bh + 3, 0.5f, kGrey);
    pdf.text(tx, ly + bh + 12, signedFmt(k == 0 ? "%.0f" : "%+.0f", 1000 * range_m * k / 2), 8, false, kBlack,
             k == -2 ? Align::Left : k == 2 ? Align::Right : Align::Centre);
  }
  ly += bh + 28;
  ly = pdf.paragraph(lx, ly, lw,
                     "Signed distance of the flying shape to the design surface: + to leeward (fuller than "
                     "designed), − to windward.",
                     8.5f, false, kGrey) + 4;
  const DistanceStats& s = c.deviation;
  pdf.paragraph(lx, ly, lw,
                "Mean " + signedFmt("%+.1f", 1000 * s.mean_m) + " mm, rms " + fmt("%.1f", 1000 * s.rms_m) +
                    " mm, 90 % between " + signedFmt("%+.1f", 1000 * s.p5_m) + " and " +
                    signedFmt("%+.1f", 1000 * s.p95_m) + " mm, largest " + fmt("%.1f", 1000 * s.max_abs_m) + " mm.",
                8.5f);
}

// The sail's outline, design beside flying: edge lengths, area, and the luff
// curve's sags (SPEC §5), each ± 1σ; a value not stored shows as "–".
float outlineTable(PdfDocument& pdf, float y, const ReportOutline& design, const ReportOutline& flying) {
  const float w = pdf.pageWidth();
  const float col[] = {kMargin + 4, kMargin + 330, kMargin + 410, kMargin + 500};  // label; right edges of the numbers
  pdf.rect(kMargin, y - 12, w - 2 * kMargin, 18, kNavy);
  pdf.text(col[0], y, "Outline", 9, true, {1, 1, 1});
  const char* heads[] = {"Design", "Flying", "Difference"};
  for (int k = 0; k < 3; ++k) pdf.text(col[k + 1], y, heads[k], 9, true, {1, 1, 1}, Align::Right);
  y += 18;
  struct Row {
    const char* label;
    OutlineMeasure ReportOutline::*field;
    const char* format;
  };
  const Row rows[] = {{"Luff length, m", &ReportOutline::luff_length_m, "%.3f"},
                      {"Leech length, m", &ReportOutline::leech_length_m, "%.3f"},
                      {"Foot length, m", &ReportOutline::foot_length_m, "%.3f"},
                      {"Top length (square top), m", &ReportOutline::top_length_m, "%.3f"},
                      {"Area, m²", &ReportOutline::area_m2, "%.2f"},
                      {"Luff sag in the sail's plane (LUFA), %", &ReportOutline::lufa_sag_pct, "%.2f"},
                      {"   its height up the luff, %", &ReportOutline::lufa_position_pct, "%.0f"},
                      {"Luff sag across it, to port (LUSW), %", &ReportOutline::lusw_sag_pct, "%.2f"},
                      {"   its height up the luff, %", &ReportOutline::lusw_position_pct, "%.0f"}};
  auto cell = [](const char* f, double v, double u, bool diff) {
    if (!std::isfinite(v)) return std::string("–");
    std::string out = signedFmt(diff ? ("%+" + std::string(f + 1)).c_str() : f, v);
    if (std::isfinite(u)) out += " ± " + fmt(f, std::abs(u));
    return out;
  };
  int band = 0;
  for (const Row& r : rows) {
    const OutlineMeasure &a = design.*r.field, &b = flying.*r.field;
    if (!std::isfinite(a.value) && !std::isfinite(b.value)) continue;  // e.g. no top edge
    if (band++ % 2) pdf.rect(kMargin, y - 10, w - 2 * kMargin, 14, kBand);
    pdf.text(col[0], y, r.label, 8.5f, false, kBlack);
    pdf.text(col[1], y, cell(r.format, a.value, a.sigma, false), 8.5f, false, kDesignBlue, Align::Right);
    pdf.text(col[2], y, cell(r.format, b.value, b.sigma, false), 8.5f, false, kFlyingRed, Align::Right);
    const double du = std::isfinite(a.sigma) || std::isfinite(b.sigma)
                          ? std::hypot(std::isfinite(a.sigma) ? a.sigma : 0.0, std::isfinite(b.sigma) ? b.sigma : 0.0)
                          : kNaN;
    pdf.text(col[3], y, cell(r.format, b.value - a.value, du, true), 8.5f, true, kBlack, Align::Right);
    y += 14;
  }
  y += 4;
  std::string note =
      "Sags are the luff's largest offset from the straight line tack to head, as % of that line's length; in the "
      "sail's plane + is away from the clew.";
  if (flying.beam_footprint_m > 0)
    note += " The flying edges were moved out " + fmt("%.1f", 100 * flying.beam_footprint_m) +
            " cm for the scanner's beam: a return lies on the sail only while the whole beam does.";
  return pdf.paragraph(kMargin, y, w - 2 * kMargin, note, 8.5f, false, kGrey);
}

void tablePage(PdfDocument& pdf, Pages& pages, const ReportData& d, const ReportStep& step, const StepComparison& c,
               const ReportOutline& design_outline) {
  float y = pages.start("Sections · " + stepLabel(d, step) + " · " + conditions(step));
  const float w = pdf.pageWidth();
  y = pdf.paragraph(kMargin, y, w - 2 * kMargin,
                    "Design and flying values per section, and the difference flying − design. The design was "
                    "analysed from its stored surface at the flying sections' heights; ± is 1σ (of the difference: "
                    "both combined).",
                    9, false, kGrey) + 8;
  const char* heads[] = {"Height", "", "Camber %", "Draft %", "Twist °", "Entry °", "Exit °"};
  const float col[] = {kMargin, kMargin + 48, kMargin + 112, kMargin + 190, kMargin + 268, kMargin + 346,
                       kMargin + 424};
  const float right[] = {0, 0, 70, 70, 70, 70, 70};  // right-aligned width of numeric columns
  pdf.rect(kMargin, y - 12, w - 2 * kMargin, 18, kNavy);
  for (int k = 0; k < 7; ++k)
    pdf.text(right[k] > 0 ? col[k] + right[k] : col[k] + 4, y, heads[k], 9, true, {1, 1, 1},
             right[k] > 0 ? Align::Right : Align::Left);
  y += 18;
  const std::vector<std::string> names = [&] {
    std::vector<double> f;
    for (const auto& s : c.sections) f.push_back(s.fraction);
    return sectionNames(f);
  }();
  for (size_t i = c.sections.size(); i-- > 0;) {  // head at the top, as on the sail
    const ComparedSection& s = c.sections[i];
    const bool converged = step.sections[i].converged;
    pdf.rect(kMargin, y - 11, w - 2 * kMargin, 3 * 13 + 2, (i % 2) ? Rgb{1, 1, 1} : kBand);
    pdf.text(col[0] + 4, y, fmt("%.0f %%", 100 * s.fraction) + (converged ? "" : " *"), 9, true);
    pdf.text(col[0] + 4, y + 13, heightName(s.fraction), 7.5f, false, kGrey);
    auto row = [&](const char* label, float yy, const SectionParameters& v, const SectionParameters& u, bool diff,
                   const Rgb& colour) {
      pdf.text(col[1], yy, label, 8.5f, diff, colour);
      const double vals[5] = {v.camber_pct, v.draft_pct, v.twist_deg, v.entry_deg, v.exit_deg};
      const double us[5] = {u.camber_pct, u.draft_pct, u.twist_deg, u.entry_deg, u.exit_deg};
      for (int k = 0; k < 5; ++k) {
        const char* f = k == 0 ? (diff ? "%+.2f" : "%.2f") : (diff ? "%+.1f" : "%.1f");
        const char* fu = k == 0 ? "%.2f" : "%.1f";
        std::string cell = std::isfinite(vals[k]) ? signedFmt(f, vals[k]) : "–";
        if (std::isfinite(vals[k]) && std::isfinite(us[k])) cell += " ± " + fmt(fu, us[k]);
        pdf.text(col[k + 2] + right[k + 2], yy, cell, 8.5f, diff, colour, Align::Right);
      }
    };
    SectionParameters delta, du;
    auto dif = [](double a, double b) { return b - a; };
    delta.camber_pct = dif(s.design.camber_pct, s.flying.camber_pct);
    delta.draft_pct = dif(s.design.draft_pct, s.flying.draft_pct);
    delta.twist_deg = dif(s.design.twist_deg, s.flying.twist_deg);
    delta.entry_deg = dif(s.design.entry_deg, s.flying.entry_deg);
    delta.exit_deg = dif(s.design.exit_deg, s.flying.exit_deg);
    du.camber_pct = std::hypot(s.design_u.camber_pct, s.flying_u.camber_pct);
    du.draft_pct = std::hypot(s.design_u.draft_pct, s.flying_u.draft_pct);
    du.twist_deg = std::hypot(s.design_u.twist_deg, s.flying_u.twist_deg);
    du.entry_deg = std::hypot(s.design_u.entry_deg, s.flying_u.entry_deg);
    du.exit_deg = std::hypot(s.design_u.exit_deg, s.flying_u.exit_deg);
    row("design", y, s.design, s.design_u, false, kDesignBlue);
    row("flying", y + 13, s.flying, s.flying_u, false, kFlyingRed);
    row("difference", y + 26, delta, du, true, kBlack);
    y += 3 * 13 + 4;
    (void)names;
  }
  y += 10;
  bool any_unconverged = false;
  for (const auto& s : step.sections) any_unconverged |= !s.converged;
  if (any_unconverged)
    y = pdf.paragraph(kMargin, y, w - 2 * kMargin,
                      "* the section plane did not reach the surface normal at maximum camber; its values are less "
                      "certain than the ± says.",
                      8.5f, false, kGrey);
  for (const UnmeasuredSection& u : step.unmeasured)
    y = pdf.paragraph(kMargin, y, w - 2 * kMargin,
                      fmt("The %.0f %% section was not measured: ", 100 * u.fraction) + u.reason + ".", 8.5f, false,
                      kFlyingRed);
  y = pdf.paragraph(kMargin, y, w - 2 * kMargin,
                    "Chord: " + [&] {
                      std::string out;
                      for (size_t i = 0; i < c.sections.size(); ++i)
                        out += (i ? ", " : "") + fmt("%.0f %%", 100 * c.sections[i].fraction) + " " +
                               fmtPm("%.3f", c.sections[i].flying.chord_m, c.sections[i].flying_u.chord_m) + " m";
                      return out;
                    }() + " (flying).",
                    8.5f, false, kGrey);
  outlineTable(pdf, y + 14, design_outline, step.outline);
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
  pdf.text(w - kMargin, y + 4, "depth drawn 2× its true scale", 8.5f, false, kGrey, Align::Right);
  y += 18;
  const auto& fractions = r.design_sections.sections;
  const size_t n = fractions.size();
  const int cols = n > 4 ? 2 : 1;
  const int rows = static_cast<int>((n + cols - 1) / cols);
  const float cw = (w - 2 * kMargin - (cols - 1) * 14) / cols;
  const float ch = std::min(150.f, (pdf.pageHeight() - y - 50) / rows);
  for (size_t k = 0; k < n; ++k) {
    const size_t idx = n - 1 - k;  // head first
    const double f = fractions[idx].fraction;
    const float x0 = kMargin + (k % cols) * (cw + 14), y0 = y + (k / cols) * ch;
    pdf.text(x0, y0 + 10, fmt("%.0f %% height", 100 * f) + " · " + heightName(f), 9, true, kNavy);
    const float px = x0 + 4, pw = cw - 8, base = y0 + ch - 16;
    const float scale = pw;  // points per chord
    const float exaggerate = 2.0f;
    pdf.line(px, base, px + pw, base, 0.5f, kRule, true);  // the chord
    auto draw = [&](const std::vector<Vec3>& curve, const Rgb& colour, bool dashed) {
      std::vector<std::pair<float, float>> line;
      for (const auto& [u, v] : chordProfile(curve)) line.emplace_back(px + u * scale, base - exaggerate * v * scale);
      pdf.polyline(line, 1.3f, colour, dashed);
    };
    draw(fractions[idx].curve, kDesignBlue, true);
    for (size_t i = 0; i < d.steps.size(); ++i)
      for (const ReportSection& s : d.steps[i].sections)
        if (std::abs(s.fraction - f) < 1e-6) draw(s.curve, stepColour(i, d.steps.size()), false);
    pdf.text(px, base + 10, "luff", 7, false, kGrey);
    pdf.text(px + pw, base + 10, "leech", 7, false, kGrey, Align::Right);
  }
}

// Table of steps: conditions, controls, forces; each with its change from the
// previous step below. Returns the y below the table.
float stepsTable(PdfDocument& pdf, float y, const ReportData& d, const std::set<std::string>& control_names) {
  const float w = pdf.pageWidth();
  std::vector<std::string> heads = {"Step", "AWA °", "AWS m/s"};
  for (const auto& c : control_names) heads.push_back(c);
  heads.insert(heads.end(), {"Drive N", "Side N", "Heel N·m"});
  const float cw = (w - 2 * kMargin) / heads.size();
  pdf.rect(kMargin, y - 12, w - 2 * kMargin, 18, kNavy);
  for (size_t k = 0; k < heads.size(); ++k)
    pdf.text(kMargin + cw * (k + 1) - 4, y, heads[k], 8.5f, true, {1, 1, 1}, Align::Right);
  y += 18;
  auto value = [&](const ReportStep& s, size_t k) -> double {
    if (k == 1) return s.awa_deg.value_or(kNaN);
    if (k == 2) return s.aws_m_s.value_or(kNaN);
    if (k < 3 + control_names.size()) {
      auto it = std::next(control_names.begin(), long(k - 3));
      auto f = s.controls.find(*it);
      return f == s.controls.end() ? kNaN : f->second;
    }
    const size_t j = k - 3 - control_names.size();
    return (j == 0 ? s.drive_n : j == 1 ? s.side_n : s.heel_moment_nm).value_or(kNaN);
  };
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const ReportStep& s = d.steps[i];
    pdf.rect(kMargin, y - 11, w - 2 * kMargin, 26, (i % 2) ? Rgb{1, 1, 1} : kBand);
    pdf.disc(kMargin + 6, y - 3, 3, stepColour(i, d.steps.size()));
    pdf.text(kMargin + cw - 4, y, std::to_string(s.step_order), 9, true, kBlack, Align::Right);
    for (size_t k = 1; k < heads.size(); ++k) {
      const bool control = k >= 3 && k < 3 + control_names.size();
      pdf.text(kMargin + cw * (k + 1) - 4, y, fmt(control ? "%.3g" : k <= 2 ? "%.1f" : "%.0f", value(s, k)), 9, false,
               kBlack, Align::Right);
      if (i > 0)
        pdf.text(kMargin + cw * (k + 1) - 4, y + 11,
                 "Δ " + signedFmt(control ? "%+.3g" : k <= 2 ? "%+.1f" : "%+.0f", value(s, k) - value(d.steps[i - 1], k)),
                 7.5f, false, kGrey, Align::Right);
    }
    y += 28;
  }
  return y;
}

// Which step pulled best, when forces were measured; returns the y below it.
float bestStepLine(PdfDocument& pdf, float y, const ReportData& d) {
  const ReportStep* most_drive = nullptr;
  const ReportStep* best_ratio = nullptr;
  for (const auto& s : d.steps) {
    if (s.drive_n && (!most_drive || *s.drive_n > *most_drive->drive_n)) most_drive = &s;
    if (s.drive_n && s.side_n && *s.side_n > 0 &&
        (!best_ratio || *s.drive_n / *s.side_n > *best_ratio->drive_n / *best_ratio->side_n))
      best_ratio = &s;
  }
  if (!most_drive) return y;
  std::string best = "Most drive: " + stepLabel(d, *most_drive) + " (" + fmt("%.0f N", *most_drive->drive_n) + ")";
  if (best_ratio)
    best += "; best drive for its side force: " + stepLabel(d, *best_ratio) + " (drive/side " +
            fmt("%.2f", *best_ratio->drive_n / *best_ratio->side_n) + ")";
  return pdf.paragraph(kMargin, y + 4, pdf.pageWidth() - 2 * kMargin, best + ".", 9.5f, true, kNavy);
}

// Controls that moved from step a to step b, and the force changes, in words.
std::string controlsAndForcesInWords(const ReportStep& a, const ReportStep& b,
                                     const std::set<std::string>& control_names) {
  std::string moved;
  for (const auto& c : control_names) {
    const auto fa = a.controls.find(c), fb = b.controls.find(c);
    if (fa == a.controls.end() || fb == b.controls.end() || fa->second == fb->second) continue;
    moved += (moved.empty() ? "" : ", ") + c + " " + fmt("%.3g", fa->second) + " → " + fmt("%.3g", fb->second);
  }
  std::string forces;
  if (a.drive_n && b.drive_n) forces += "drive " + signedFmt("%+.0f", *b.drive_n - *a.drive_n) + " N";
  if (a.side_n && b.side_n) forces += (forces.empty() ? "" : ", ") + std::string("side ") + signedFmt("%+.0f", *b.side_n - *a.side_n) + " N";
  if (a.heel_moment_nm && b.heel_moment_nm)
    forces += (forces.empty() ? "" : ", ") + std::string("heel ") + signedFmt("%+.0f", *b.heel_moment_nm - *a.heel_moment_nm) + " N·m";
  return "Controls: " + (moved.empty() ? std::string("no change recorded") : moved) + ". Forces: " +
         (forces.empty() ? std::string("not measured") : forces) + ".";
}

// The same section in two steps (matched by fraction).
struct SectionPair {
  const ReportSection *a, *b;
};

std::vector<SectionPair> matchSections(const ReportStep& a, const ReportStep& b) {
  std::vector<SectionPair> pairs;
  for (const auto& sb : b.sections)
    for (const auto& sa : a.sections)
      if (std::abs(sa.fraction - sb.fraction) < 1e-6) pairs.push_back({&sa, &sb});
  return pairs;
}

// For the crew: camber, draft and twist changes as their mean over the
// sections and the largest one with where it is.
std::string shapeChangeInWords(const std::vector<SectionPair>& pairs) {
  const char* label[3] = {"camber", "draft", "twist"};
  double SectionParameters::*fields[3] = {&SectionParameters::camber_pct, &SectionParameters::draft_pct,
                                          &SectionParameters::twist_deg};
  const char* unit[3] = {" % of chord", " % of chord", "°"};
  std::string words;
  for (int k = 0; k < 3; ++k) {
    double sum = 0, best = 0, best_f = 0;
    int n = 0;
    for (const auto& p : pairs) {
      const double dv = p.b->value.*fields[k] - p.a->value.*fields[k];
      if (!std::isfinite(dv)) continue;
      sum += dv, ++n;
      if (std::abs(dv) > std::abs(best)) best = dv, best_f = p.b->fraction;
    }
    if (!n) continue;
    // Changes below half a tenth do not print as a change at one decimal.
    if (std::abs(best) < 0.05) {
      words += std::string(words.empty() ? "" : "; ") + label[k] + " unchanged";
      continue;
    }
    words += std::string(words.empty() ? "" : "; ") + label[k] + " " + signedFmt("%+.1f", sum / n) + unit[k] +
             " on average, most at the " + heightName(best_f) + " (" + signedFmt("%+.1f", best) + unit[k] + ")";
  }
  return "Shape: " + words + ".";
}

// For the designer: every parameter's change per section ± its 1σ (the two
// steps' σ in quadrature), head at the top. Returns the y below the table.
float sectionChangeTable(PdfDocument& pdf, float y, const std::vector<SectionPair>& pairs) {
  const float w = pdf.pageWidth();
  const char* h2[] = {"Height", "Δ camber %", "Δ draft %", "Δ twist °", "Δ entry °", "Δ exit °"};
  const float c2 = (w - 2 * kMargin) / 6;
  pdf.rect(kMargin, y - 10, w - 2 * kMargin, 15, kLightGrey);
  for (int k = 0; k < 6; ++k) pdf.text(kMargin + c2 * (k + 1) - 4, y, h2[k], 8, true, kBlack, Align::Right);
  y += 14;
  for (size_t q = pairs.size(); q-- > 0;) {
    const auto& p = pairs[q];
    pdf.text(kMargin + c2 - 4, y, fmt("%.0f %%", 100 * p.b->fraction), 8, false, kBlack, Align::Right);
    double SectionParameters::*fields[5] = {&SectionParameters::camber_pct, &SectionParameters::draft_pct,
                                            &SectionParameters::twist_deg, &SectionParameters::entry_deg,
                                            &SectionParameters::exit_deg};
    for (int k = 0; k < 5; ++k) {
      const double dv = p.b->value.*fields[k] - p.a->value.*fields[k];
      const double du = std::hypot(p.b->uncertainty.*fields[k], p.a->uncertainty.*fields[k]);
      const char* f = k == 0 ? "%+.2f" : "%+.1f";
      std::string cell = std::isfinite(dv) ? signedFmt(f, dv) : "–";
      if (std::isfinite(dv) && std::isfinite(du)) cell += " ± " + fmt(k == 0 ? "%.2f" : "%.1f", du);
      pdf.text(kMargin + c2 * (k + 2) - 4, y, cell, 8, false, kBlack, Align::Right);
    }
    y += 12;
  }
  return y;
}

void changesPage(PdfDocument& pdf, Pages& pages, const TrimReportData& r, bool crew) {
  const ReportData& d = r.data;
  float y = pages.start("Trim steps: what changed");
  const float w = pdf.pageWidth();
  std::set<std::string> control_names;
  for (const auto& s : d.steps)
    for (const auto& [k, v] : s.controls) control_names.insert(k);
  y = stepsTable(pdf, y, d, control_names);
  y = bestStepLine(pdf, y, d) + 12;
  for (size_t i = 1; i < d.steps.size(); ++i) {
    const ReportStep &a = d.steps[i - 1], &b = d.steps[i];
    pdf.text(kMargin, y, stepLabel(d, a) + " → " + stepLabel(d, b), 11, true, kNavy);
    y += 16;
    y = pdf.paragraph(kMargin, y, w - 2 * kMargin, controlsAndForcesInWords(a, b, control_names), 9.5f) + 2;
    const std::vector<SectionPair> pairs = matchSections(a, b);
    if (crew) {
      y = pdf.paragraph(kMargin, y, w - 2 * kMargin, shapeChangeInWords(pairs), 9.5f) + 10;
      continue;
    }
    y = sectionChangeTable(pdf, y, pairs) + 12;
    if (y > pdf.pageHeight() - 140 && i + 1 < d.steps.size()) y = pages.start("Trim steps: what changed (continued)");
  }
}

void requireWritable(const std::string& out) {
  if (out.empty()) throw InvalidInput("[writeTrimReport] no output file given");
  const std::filesystem::path p(out);
  if (std::filesystem::is_directory(p)) throw InvalidInput("[writeTrimReport] output " + out + " is a directory");
  const std::filesystem::path dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
  if (!std::filesystem::is_directory(dir))
    throw InvalidInput("[writeTrimReport] cannot write " + out + ": folder " + dir.string() + " does not exist");
  if (access(dir.c_str(), W_OK) != 0 || (std::filesystem::exists(p) && access(out.c_str(), W_OK) != 0))
    throw InvalidInput("[writeTrimReport] cannot write " + out + ": permission denied");
}

void validate(const TrimReportParams& p) {
  if (p.audience != "crew" && p.audience != "designer")
    throw InvalidInput("[writeTrimReport] audience must be crew or designer (got \"" + p.audience + "\")");
  if (p.scan_id.has_value() == !p.test.empty())
    throw InvalidInput("[writeTrimReport] give exactly one of a scan id and a test name");
  if (p.db_path.empty()) throw InvalidInput("[writeTrimReport] no database given");
  if (!isPostgresUrl(p.db_path) && !std::filesystem::exists(p.db_path))
    throw InvalidInput("[writeTrimReport] database " + p.db_path + " does not exist");
}

}  // namespace

Mesh loftSections(const std::vector<ReportSection>& sections, int columns, int rows_between) {
  std::vector<std::vector<Vec3>> curves;
  for (const auto& s : sections)
    if (s.curve.size() >= 2) curves.push_back(resampleByArc(s.curve, columns));
  if (curves.size() < 2)
    throw InvalidInput("[loftSections] a flying surface needs at least two section curves (got " +
                       std::to_string(curves.size()) + ")");
  if (columns < 2 || rows_between < 0)
    throw InvalidInput("[loftSections] columns must be >= 2 and rows_between >= 0 (got " + std::to_string(columns) +
                       ", " + std::to_string(rows_between) + ")");
  Mesh mesh;
  const int per = rows_between + 1;
  const int rows = static_cast<int>(curves.size() - 1) * per + 1;
  for (int r = 0; r < rows; ++r) {
    const size_t i = std::min(static_cast<size_t>(r / per), curves.size() - 2);
    const double t = double(r - int(i) * per) / per;
    for (int c = 0; c < columns; ++c) mesh.vertices.push_back((1 - t) * curves[i][c] + t * curves[i + 1][c]);
  }
  for (int r = 0; r + 1 < rows; ++r)
    for (int c = 0; c + 1 < columns; ++c) {
      const uint32_t a = r * columns + c, b = a + 1, e = a + columns, f = e + 1;
      mesh.triangles.push_back({a, b, f});
      mesh.triangles.push_back({a, f, e});
    }
  return mesh;
}

TrimReportData prepareTrimReport(const TrimReportParams& p, const Progress& progress) {
  validate(p);
  progress("loading", 0);
  OpenOptions oo;
  oo.create = false;
  oo.read_only = true;
  oo.busy_timeout_ms = p.busy_timeout_ms;
  Database db = openSailDatabase(p.db_path, oo);
  TrimReportData r;
  r.data = p.scan_id ? loadScanReport(db, *p.scan_id) : loadTestReport(db, p.test, p.sail);
  if (!r.data.design_mesh)
    throw InvalidInput("[prepareTrimReport] sail \"" + r.data.sail + "\" has no design mesh in " + p.db_path +
                       " (store one with the sail's design)");
  progress("loading", 1);

  progress("design", 0);
  SectionParams sp;
  std::set<double> fractions;
  for (const auto& s : r.data.steps)
    for (const auto& sec : s.sections) fractions.insert(sec.fraction);
  sp.fractions.assign(fractions.begin(), fractions.end());
  sp.sensor_sigma_m = 0;  // an exact surface: what is left is the resampling's own scatter
  const MeshSections design = analyzeMeshSections(*r.data.design_mesh, {}, sp, p.design_sampling);
  r.design_sections = design.sections;
  r.design_outline = reportOutline(design.outline, measureLuffCurve(design.outline));
  r.warnings = design.sections.warnings;
  r.notes = design.notes;
  progress("design", 0.6);

  const DesignDistance distance(*r.data.design_mesh);
  r.warnings.insert(r.warnings.end(), distance.warnings().begin(), distance.warnings().end());
  for (const ReportStep& step : r.data.steps) {
    StepComparison c;
    for (const ReportSection& fs : step.sections) {
      ComparedSection cs;
      cs.fraction = fs.fraction;
      cs.flying = fs.value;
      cs.flying_u = fs.uncertainty;
      // A design section left unmeasured shows as "–", not as a design of zeros.
      const double nan = std::numeric_limits<double>::quiet_NaN();
      cs.design = cs.design_u = {nan, nan, nan, nan, nan, nan, nan};
      for (const Section& ds : r.design_sections.sections)
        if (std::abs(ds.fraction - fs.fraction) < 1e-9) cs.design = ds.value, cs.design_u = ds.uncertainty;
      c.sections.push_back(cs);
    }
    if (step.sections.size() < 2) {
      std::string gone;
      for (const UnmeasuredSection& u : step.unmeasured) gone += (gone.empty() ? "" : ", ") + fmt("%.0f %%", 100 * u.fraction);
      throw InvalidInput("[writeTrimReport] scan " + std::to_string(step.scan_id) + " has " +
                         std::to_string(step.sections.size()) + " measured section" +
                         (gone.empty() ? "" : " (not measured: " + gone + ")") +
                         "; its flying surface needs at least two");
    }
    c.flying_surface = loftSections(step.sections);
    c.deviation_m = signedDistances(distance, c.flying_surface.vertices);
    c.deviation = distanceStats(c.deviation_m);
    r.steps.push_back(std::move(c));
  }
  r.summary = summarizeDifferences(r.steps.back().sections, p.summary);
  progress("design", 1);
  return r;
}

TrimReport writeTrimReport(const TrimReportParams& p, const Progress& progress) {
  validate(p);
  requireWritable(p.out_path);
  PdfDocument pdf(p.fonts);  // a missing font fails before the work
  TrimReport out;
  out.content = prepareTrimReport(p, progress);
  const TrimReportData& r = out.content;
  const bool crew = p.audience == "crew";

  // Each step's colour scale spans its own 5–95 % deviations (at least ±5 mm,
  // about the sensor's σ, SPEC §3): a step close to the design still shows where it differs.
  auto rangeOf = [](const StepComparison& c) {
    return niceCeil(std::max({std::abs(c.deviation.p5_m), std::abs(c.deviation.p95_m), 0.005}) * 1000) / 1000;
  };

  progress("rendering", 0);
  std::vector<SailViews> views;
  {
    PrivateDisplay display;
    out.private_display = display.started();
    RenderParams rp = p.render;
    const size_t first = crew ? r.steps.size() - 1 : 0;
    for (size_t i = first; i < r.steps.size(); ++i) {
      rp.deviation_range_m = rangeOf(r.steps[i]);
      views.push_back(renderSailViews(*r.data.design_mesh, r.steps[i].flying_surface, r.steps[i].deviation_m, rp));
      progress("rendering", double(i + 1 - first) / (r.steps.size() - first));
    }
  }

  progress("writing", 0);
  pdf.setInfo("Sail shape report: " + r.data.sail, "sailshape",
              (r.data.test.empty() ? "scan " + std::to_string(r.data.steps.front().scan_id) : "test " + r.data.test) +
                  ", " + p.audience);
  Pages pages(pdf, r.data);
  coverPage(pdf, pages, r, crew);
  const ReportData& d = r.data;
  if (crew) {
    viewsPage(pdf, pages, d, d.steps.back(), r.steps.back(), views.back(), rangeOf(r.steps.back()));
    plotsPage(pdf, pages, r, true);
  } else {
    for (size_t i = 0; i < d.steps.size(); ++i) viewsPage(pdf, pages, d, d.steps[i], r.steps[i], views[i], rangeOf(r.steps[i]));
    for (size_t i = 0; i < d.steps.size(); ++i) tablePage(pdf, pages, d, d.steps[i], r.steps[i], r.design_outline);
    plotsPage(pdf, pages, r, false);
    curvesPage(pdf, pages, r);
  }
  if (d.steps.size() > 1) changesPage(pdf, pages, r, crew);
  pdf.save(p.out_path);
  out.out_path = p.out_path;
  out.pages = pdf.pageCount();
  progress("writing", 1);
  return out;
}

}  // namespace sailshape
