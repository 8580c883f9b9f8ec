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
#include "reports/report_layout.hpp"

namespace sailshape {
namespace {

using namespace layout;

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

// The deviation colour scale from −range to +range, `w` wide at (x, y), labelled at −, −½, 0,
// +½, + range in `to_units` × the value printed with `f`. Returns the y below its labels.
float colourScale(PdfDocument& pdf, float x, float y, float w, double range, double to_units, const char* f) {
  const float bh = 10;
  const int n = 100;
  for (int i = 0; i < n; ++i) {
    const double t = -range + 2 * range * (i + 0.5) / n;
    pdf.rect(x + w * i / n, y, w / n + 0.3f, bh, deviationColour(t, range));
  }
  pdf.frame(x, y, w, bh, 0.4f, kRule);
  for (int k = -2; k <= 2; ++k) {
    const float tx = x + w * (k + 2) / 4.0f;
    pdf.line(tx, y + bh, tx, y + bh + 3, 0.5f, kGrey);
    pdf.text(tx, y + bh + 12, signedFmt(k == 0 ? "%.0f" : f, to_units * range * k / 2), 8, false, kBlack,
             k == -2 ? Align::Left : k == 2 ? Align::Right : Align::Centre);
  }
  return y + bh + 22;
}

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
  place(v.side, x, y, L.side_w, L.row1_h, "From the side (starboard), bow to the right");
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
  ly = pdf.paragraph(lx + 24, ly, lw - 24,
                     c.lofted ? "flying shape, lofted through the measured sections (the scan's surface was not stored)"
                              : "flying shape, the surface reconstructed from the scan",
                     8.5f) + 14;
  pdf.text(lx, ly, "Deviation, mm", 9.5f, true, kNavy);
  ly = colourScale(pdf, lx, ly + 10, lw, range_m, 1000, "%+.0f") + 6;
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

// The pictures of the design-moved page.
struct MovedViews {
  RgbImage normal, stretch;
  double normal_range_m = 0, stretch_range_pct = 0;
};

// "Where the design moved": the design fitted onto the last step's surface, its move along its
// normal and its stretch, side by side, the inferred parts drawn pale, and the numbers beneath.
void movedPage(PdfDocument& pdf, Pages& pages, const ReportData& d, const ReportStep& step, const DesignMoved& m,
               const MovedViews& v) {
  float y = pages.start("Where the design moved · " + stepLabel(d, step));
  const ViewLayout L;
  const float w = L.side_w, h = L.row1_h, gap = 60;
  float x = 0.5f * (pdf.pageWidth() - 2 * w - gap);
  struct Panel {
    const RgbImage& image;
    std::string caption, unit;
    double range, to_units;
    const char* f;
  } panels[] = {{v.normal, "Move along the design's normal", "mm, + to leeward", v.normal_range_m, 1000, "%+.0f"},
                {v.stretch, "Stretch of the cloth", "% of the design's lengths", v.stretch_range_pct, 1, "%+.1f"}};
  for (const Panel& p : panels) {
    pdf.image(p.image, x, y, w, h);
    pdf.frame(x, y, w, h, 0.5f, kRule);
    pdf.text(x + w / 2, y + h + 12, p.caption + ", " + p.unit, 8.5f, false, kBlack, Align::Centre);
    colourScale(pdf, x, y + h + 22, w, p.range, p.to_units, p.f);
    x += w + gap;
  }
  // Beneath the pictures: what pale means, and the numbers.
  const float lx = kMargin, lw = pdf.pageWidth() - 2 * kMargin;
  float ly = y + h + 72;
  const DesignFit& f = m.fit;
  pdf.text(lx, ly, "The design fitted to the scan", 9.5f, true, kNavy);
  ly = pdf.paragraph(lx, ly + 14, lw,
                     "Each point of the design, moved to where the sail flew: through the scan's samples where "
                     "it has them, carried on smoothly from around where it has none.",
                     8.5f) + 8;
  pdf.rect(lx, ly - 8, 18, 8, mutedColour(deviationColour(0, v.normal_range_m)));
  ly = pdf.paragraph(lx + 24, ly, lw - 24,
                     "pale: inferred, no sample within " + fmt("%.0f", 1000 * f.support_radius_m) + " mm (" +
                         fmt("%.0f", 100 * (1 - f.coverage)) + " % of the area)",
                     8.5f) + 10;
  auto stats = [&](const std::string& what, const DistanceStats& s) {
    ly = pdf.paragraph(lx, ly, lw,
                       what + ": mean " + signedFmt("%+.0f", 1000 * s.mean_m) + " mm, 90 % between " +
                           signedFmt("%+.0f", 1000 * s.p5_m) + " and " + signedFmt("%+.0f", 1000 * s.p95_m) + " mm.",
                       8.5f) + 6;
  };
  stats("Scanned, along the normal", m.normal_scanned);
  if (m.normal_inferred.count > 0) {
    stats("Inferred, along the normal", m.normal_inferred);
    ly = pdf.paragraph(lx, ly, lw,
                       "Where inferred the fit is known to ±" + fmt("%.0f", 1000 * m.inferred_sigma_p50_m) +
                           " mm (1σ, median): more near the last samples, less far from them.",
                       8.5f, false, kGrey) + 6;
  }
  ly = pdf.paragraph(lx, ly, lw,
                     "Along the sail, scanned: median " + fmt("%.0f", 1000 * m.along_scanned.p50_m) + " mm, 95 % under " +
                         fmt("%.0f", 1000 * m.along_scanned.p95_m) + " mm.",
                     8.5f) + 6;
  ly = pdf.paragraph(lx, ly, lw,
                     "Stretch where scanned: 90 % between " + signedFmt("%+.2f", f.strain_supported.p5_pct) + " and " +
                         signedFmt("%+.2f", f.strain_supported.p95_pct) + " %. Through the samples: RMS " +
                         fmt("%.1f", 1000 * f.rms_m) + " mm.",
                     8.5f) + 6;
  for (const std::string& warning : f.warnings) ly = pdf.paragraph(lx, ly, lw, warning, 8, false, kGrey) + 4;
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
    OutlineMeasure ReportOutline::*sag = nullptr;  // a sag, or the sag a position belongs to
  };
  const Row rows[] = {{"Luff length, m", &ReportOutline::luff_length_m, "%.3f"},
                      {"Leech length, m", &ReportOutline::leech_length_m, "%.3f"},
                      {"Foot length, m", &ReportOutline::foot_length_m, "%.3f"},
                      {"Top length (square top), m", &ReportOutline::top_length_m, "%.3f"},
                      {"Area, m²", &ReportOutline::area_m2, "%.2f"},
                      {"Luff sag in the sail's plane (LUFA), %", &ReportOutline::lufa_sag_pct, "%.2f",
                       &ReportOutline::lufa_sag_pct},
                      {"   its height up the luff, %", &ReportOutline::lufa_position_pct, "%.0f",
                       &ReportOutline::lufa_sag_pct},
                      {"Luff sag across it, to port (LUSW), %", &ReportOutline::lusw_sag_pct, "%.2f",
                       &ReportOutline::lusw_sag_pct},
                      {"   its height up the luff, %", &ReportOutline::lusw_position_pct, "%.0f",
                       &ReportOutline::lusw_sag_pct}};
  auto cell = [](const char* f, double v, double u, bool diff) {
    if (!std::isfinite(v)) return std::string("–");
    std::string out = signedFmt(diff ? ("%+" + std::string(f + 1)).c_str() : f, v);
    if (std::isfinite(u)) out += " ± " + fmt(f, std::abs(u));
    return out;
  };
  // A sag within 2σ of zero is not a sag the scan found (the summary's threshold,
  // SummaryParams::min_sigmas): it reads "none", and where along the luff it stands
  // is no result either; nor is a position whose σ exceeds it.
  auto resolved = [](const OutlineMeasure& sag) {
    return std::isfinite(sag.value) && !(std::isfinite(sag.sigma) && std::abs(sag.value) <= 2 * sag.sigma);
  };
  auto isResult = [&](const Row& r, const ReportOutline& o) {
    const OutlineMeasure& m = o.*r.field;
    if (!r.sag || !std::isfinite(m.value)) return true;
    if (!resolved(o.*r.sag)) return false;
    return r.sag == r.field || !(std::isfinite(m.sigma) && m.sigma >= std::abs(m.value));
  };
  auto shown = [&](const Row& r, const ReportOutline& o) -> std::string {
    const OutlineMeasure& m = o.*r.field;
    if (!isResult(r, o)) return r.sag == r.field ? "none (± " + fmt(r.format, m.sigma) + ")" : "–";
    return cell(r.format, m.value, m.sigma, false);
  };
  int band = 0;
  for (const Row& r : rows) {
    const OutlineMeasure &a = design.*r.field, &b = flying.*r.field;
    if (!std::isfinite(a.value) && !std::isfinite(b.value)) continue;  // e.g. no top edge
    if (band++ % 2) pdf.rect(kMargin, y - 10, w - 2 * kMargin, 14, kBand);
    pdf.text(col[0], y, r.label, 8.5f, false, kBlack);
    pdf.text(col[1], y, shown(r, design), 8.5f, false, kDesignBlue, Align::Right);
    pdf.text(col[2], y, shown(r, flying), 8.5f, false, kFlyingRed, Align::Right);
    const double du = std::isfinite(a.sigma) || std::isfinite(b.sigma)
                          ? std::hypot(std::isfinite(a.sigma) ? a.sigma : 0.0, std::isfinite(b.sigma) ? b.sigma : 0.0)
                          : kNaN;
    // Two positions compare only where both sags were found.
    const bool comparable = !r.sag || r.sag == r.field || (isResult(r, design) && isResult(r, flying));
    pdf.text(col[3], y, comparable ? cell(r.format, b.value - a.value, du, true) : "–", 8.5f, true, kBlack,
             Align::Right);
    y += 14;
  }
  y += 4;
  std::string note =
      "Sags are the luff's largest offset from the straight line tack to head, as % of that line's length; in the "
      "sail's plane + is away from the clew. A sag within 2σ of zero reads \"none\"; a height whose σ exceeds it is not given.";
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

namespace {

// The design fitted onto a step's surface (analysis/fit), and what the page shows of it.
DesignMoved designMoved(const Mesh& design, const std::vector<Vec3>& surface, const Vec3& leeward,
                        const Progress& progress) {
  DesignMoved m;
  m.fit = fitDesign(design, surface, {}, progress);
  const size_t n = design.vertices.size();
  VertexMoves moves = vertexMoves(design, m.fit, leeward);
  m.normal_m = std::move(moves.normal_m);
  m.along_m = std::move(moves.along_m);
  m.stretch_pct = vertexStretchPct(m.fit);
  m.inferred.resize(n);
  std::vector<double> scanned, inferred, along, sigma;
  for (size_t v = 0; v < n; ++v) {
    m.inferred[v] = !m.fit.supported[v];
    if (m.inferred[v]) {
      inferred.push_back(m.normal_m[v]);
      sigma.push_back(m.fit.sigma_m[v]);
    } else {
      scanned.push_back(m.normal_m[v]);
      along.push_back(m.along_m[v]);
    }
  }
  if (!scanned.empty()) m.normal_scanned = distanceStats(scanned);
  if (!inferred.empty()) m.normal_inferred = distanceStats(inferred);
  if (!along.empty()) m.along_scanned = distanceStats(along);
  if (!sigma.empty()) {
    std::nth_element(sigma.begin(), sigma.begin() + sigma.size() / 2, sigma.end());
    m.inferred_sigma_p50_m = sigma[sigma.size() / 2];
  }
  return m;
}

}  // namespace

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
    if (step.surface && !step.surface->empty()) {
      c.flying_surface = *step.surface;
    } else {
      // Scans stored before their analysis kept its surface (schema version 4), or
      // imported from the analysis JSON alone: the section curves stand in for it.
      if (step.sections.size() < 2) {
        std::string gone;
        for (const UnmeasuredSection& u : step.unmeasured)
          gone += (gone.empty() ? "" : ", ") + fmt("%.0f %%", 100 * u.fraction);
        throw InvalidInput("[writeTrimReport] scan " + std::to_string(step.scan_id) + " has " +
                           std::to_string(step.sections.size()) + " measured section" +
                           (gone.empty() ? "" : " (not measured: " + gone + ")") +
                           " and no stored surface; its flying surface needs at least two");
      }
      c.flying_surface = loftSections(step.sections);
      c.lofted = true;
    }
    c.deviation_m = signedDistances(distance, c.flying_surface.vertices);
    c.deviation = distanceStats(c.deviation_m);
    r.steps.push_back(std::move(c));
  }
  r.summary = summarizeDifferences(r.steps.back().sections, p.summary);
  progress("design", 1);
  if (const ReportStep& last = r.data.steps.back(); p.audience == "designer" && last.surface && !last.surface->empty())
    r.moved = designMoved(*r.data.design_mesh, last.surface->vertices, distance.leeward(), progress);
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

  // One colour scale for the whole report, so a colour means the same millimetres on
  // every page: it spans the largest 5–95 % deviation of any step (at least ±5 mm,
  // about the sensor's σ, SPEC §3).
  double spread_m = 0.005;
  for (const StepComparison& c : r.steps)
    spread_m = std::max({spread_m, std::abs(c.deviation.p5_m), std::abs(c.deviation.p95_m)});
  const double range_m = niceCeil(spread_m * 1000) / 1000;
  out.deviation_range_m = range_m;

  progress("rendering", 0);
  std::vector<SailViews> views;
  MovedViews moved;
  {
    PrivateDisplay display;
    out.private_display = display.started();
    RenderParams rp = p.render;
    rp.deviation_range_m = range_m;
    const size_t first = crew ? r.steps.size() - 1 : 0;
    for (size_t i = first; i < r.steps.size(); ++i) {
      views.push_back(renderSailViews(*r.data.design_mesh, r.steps[i].flying_surface, r.steps[i].deviation_m, rp));
      progress("rendering", double(i + 1 - first) / (r.steps.size() - first));
    }
    if (r.moved) {
      // Each scale spans the larger 5–95 % of the scanned and inferred parts (at least ±5 mm, the
      // sensor's σ, and ±0.5 %, a sailcloth's stretch under load).
      const DesignMoved& m = *r.moved;
      double move = 0.005, stretch = 0.5;
      for (const DistanceStats* s : {&m.normal_scanned, &m.normal_inferred})
        if (s->count > 0) move = std::max({move, std::abs(s->p5_m), std::abs(s->p95_m)});
      stretch = std::max({stretch, std::abs(m.fit.strain_supported.p5_pct), std::abs(m.fit.strain_supported.p95_pct)});
      moved.normal_range_m = niceCeil(move * 1000) / 1000;
      moved.stretch_range_pct = niceCeil(stretch);
      moved.normal = renderColouredSide(m.fit.fitted, m.normal_m, moved.normal_range_m, m.inferred, rp.side);
      moved.stretch = renderColouredSide(m.fit.fitted, m.stretch_pct, moved.stretch_range_pct, m.inferred, rp.side);
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
    viewsPage(pdf, pages, d, d.steps.back(), r.steps.back(), views.back(), range_m);
    plotsPage(pdf, pages, r, true);
  } else {
    for (size_t i = 0; i < d.steps.size(); ++i) viewsPage(pdf, pages, d, d.steps[i], r.steps[i], views[i], range_m);
    for (size_t i = 0; i < d.steps.size(); ++i) tablePage(pdf, pages, d, d.steps[i], r.steps[i], r.design_outline);
    if (r.moved) movedPage(pdf, pages, d, d.steps.back(), *r.moved, moved);
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
