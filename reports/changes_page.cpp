// "Trim steps: what changed": the steps' conditions, controls and forces, and
// each step's shape change from the one before.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <iterator>
#include <set>

#include "reports/report_layout.hpp"
#include "reports/report_summary.hpp"

namespace sailshape::layout {
namespace {

// A control's stored key in plain words with its unit, read from the key's SI
// suffix (SPEC §2): "gennaker_tack_ease_m" → {"gennaker tack ease", "m"}.
struct ControlName {
  std::string words, unit;
};
ControlName controlName(const std::string& key) {
  static const std::pair<const char*, const char*> kUnits[] = {
      {"_m_s", "m/s"}, {"_mm", "mm"}, {"_m", "m"},   {"_deg", "°"}, {"_pct", "%"},
      {"_nm", "N·m"},  {"_n", "N"},   {"_kg", "kg"}, {"_s", "s"}};
  ControlName out{key, ""};
  for (const auto& [suffix, unit] : kUnits) {
    const std::string sfx = suffix;
    if (key.size() > sfx.size() && key.compare(key.size() - sfx.size(), sfx.size(), sfx) == 0) {
      out = {key.substr(0, key.size() - sfx.size()), unit};
      break;
    }
  }
  for (char& c : out.words)
    if (c == '_') c = ' ';
  return out;
}

// Words wrapped to `width` at `size` pt (bold), one string per line.
std::vector<std::string> wrapWords(const PdfDocument& pdf, const std::string& text, float width, float size) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    if (!lines.empty() && pdf.textWidth(lines.back() + " " + word, size, true) <= width)
      lines.back() += " " + word;
    else
      lines.push_back(word);
  }
  return lines;
}

// Table of steps: conditions, controls, forces; each with its change from the
// previous step below. Returns the y below the table.
float stepsTable(PdfDocument& pdf, float y, const ReportData& d, const std::set<std::string>& control_names) {
  const float w = pdf.pageWidth();
  std::vector<std::string> heads = {"Step", "AWA °", "AWS m/s"};
  for (const auto& c : control_names) {
    ControlName name = controlName(c);
    name.words[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(name.words[0])));
    heads.push_back(name.words + (name.unit.empty() ? "" : ", " + name.unit));
  }
  heads.insert(heads.end(), {"Drive N", "Side N", "Heel N·m"});
  const float cw = (w - 2 * kMargin) / heads.size();
  // Each heading wrapped into its own column, so a long control name takes lines, not its neighbours' room.
  std::vector<std::vector<std::string>> head_lines;
  size_t deepest = 1;
  for (const std::string& h : heads) {
    head_lines.push_back(wrapWords(pdf, h, cw - 8, 8.5f));
    deepest = std::max(deepest, head_lines.back().size());
  }
  const float line_h = 10;
  pdf.rect(kMargin, y - 12, w - 2 * kMargin, 18 + line_h * (deepest - 1), kNavy);
  for (size_t k = 0; k < heads.size(); ++k)
    for (size_t l = 0; l < head_lines[k].size(); ++l)
      pdf.text(kMargin + cw * (k + 1) - 4, y + line_h * l, head_lines[k][l], 8.5f, true, {1, 1, 1}, Align::Right);
  y += 18 + line_h * (deepest - 1);
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
    const ControlName name = controlName(c);
    moved += (moved.empty() ? "" : ", ") + name.words + " " + fmt("%.3g", fa->second) + " → " + fmt("%.3g", fb->second) +
             (name.unit.empty() ? "" : name.unit == "°" || name.unit == "%" ? name.unit : " " + name.unit);
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

}  // namespace

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

}  // namespace sailshape::layout
