#include "reports/report_layout.hpp"

#include <cmath>
#include <cstdio>

namespace sailshape::layout {

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

Rgb stepColour(size_t i, size_t n) {
  static const Rgb palette[] = {{0.85, 0.12, 0.10}, {0.95, 0.55, 0.05}, {0.55, 0.15, 0.65},
                                {0.10, 0.60, 0.30}, {0.45, 0.30, 0.15}, {0.90, 0.30, 0.60}};
  if (n == 1) return kFlyingRed;
  return palette[i % (sizeof(palette) / sizeof(palette[0]))];
}

double niceCeil(double v) {
  if (!(v > 0)) return 1;
  const double e = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * e >= v * (1 - 1e-9)) return m * e;
  return 10 * e;
}

void axisTicks(double lo, double hi, std::vector<double>& ticks) {
  const double step = niceCeil((hi - lo) / 5);
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) ticks.push_back(t);
}

void legendRow(PdfDocument& pdf, float x, float y, const std::vector<Series>& series) {
  for (const auto& s : series) {
    pdf.line(x, y - 3, x + 18, y - 3, 1.6f, s.colour, s.dashed);
    pdf.text(x + 22, y, s.label, 8.5f);
    x += 22 + pdf.textWidth(s.label, 8.5f) + 16;
  }
}

float Pages::start(const std::string& title, bool landscape) {
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

}  // namespace sailshape::layout
