// What a person sees on the report's pages, read back with poppler: the side
// view's bow where its caption says, the scanned surface over the whole sail,
// one deviation scale, curves inside their panels, plots fitted to the data,
// headings that do not overprint, controls in words, sags not found said as
// such, and no warning from poppler about the fonts.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "analysis/design/sail_generator.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "reports/private_display.hpp"
#include "reports/render_views.hpp"
#include "reports/trim_report.hpp"
#include "tests/reports/report_fixture.hpp"

namespace sailshape {
namespace {

using namespace report_test;

// A sail's test of `steps` trim steps, sections at 25, 50 and 75 % (as the demo
// cuts them), its gennaker tack eased 20 mm a step; the flying shape is the design
// with `extra_camber_pct` more camber, stored with its reconstructed surface
// (the generator's mesh of that shape over the whole sail) when `with_surface`.
// The triangles of `mesh` below `top` of its height, with only the vertices they use.
Mesh cutAbove(const Mesh& mesh, double top) {
  double lo = 1e9, hi = -1e9;
  for (const Vec3& v : mesh.vertices) lo = std::min(lo, v.z()), hi = std::max(hi, v.z());
  const double cut = lo + top * (hi - lo) + 1e-9;
  Mesh out;
  std::vector<int64_t> index(mesh.vertices.size(), -1);
  for (const auto& t : mesh.triangles) {
    if (mesh.vertices[t[0]].z() > cut || mesh.vertices[t[1]].z() > cut || mesh.vertices[t[2]].z() > cut) continue;
    std::array<uint32_t, 3> kept{};
    for (int k = 0; k < 3; ++k) {
      if (index[t[k]] < 0) {
        index[t[k]] = static_cast<int64_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[t[k]]);
      }
      kept[k] = static_cast<uint32_t>(index[t[k]]);
    }
    out.triangles.push_back(kept);
  }
  return out;
}

struct SmallTest {
  TempDir dir;
  std::string db_path = dir.file("small.sailshape");
  SailDesign design;

  // `surface_top`: the stored surface stops at this fraction of the sail's height (a scan that
  // did not reach the head).
  SmallTest(SailType type, int steps, bool with_surface, double extra_camber_pct = 1.0,
            const std::function<void(nlohmann::json&)>& edit = {}, double surface_top = 1.0)
      : design(exampleDesign(type)) {
    Database db = openSailDatabase(db_path);
    const Mesh mesh = generateSailMesh(design);
    upsertSail(db, {"A2", sailTypeName(type), "", "", "", "Demo 36"}, &mesh);
    for (int k = 0; k < steps; ++k) {
      SailDesign flying = design;
      for (auto& s : flying.stations) s.camber_pct += extra_camber_pct + 0.3 * k;
      const SailSurface surface(flying);
      nlohmann::json doc;
      doc["sections"] = nlohmann::json::array();
      for (double f : {0.25, 0.5, 0.75}) doc["sections"].push_back(flyingSection(surface, f, k));
      flyingOutline(doc, k);
      if (edit) edit(doc);
      ImportMetadata meta;
      meta.campaign = "tunnel";
      meta.sail = "A2";
      meta.test = "tack ease";
      meta.trim_step = k + 1;
      meta.awa_deg = 110;
      meta.aws_m_s = 6;
      meta.drive_n = 129.0 - k;
      meta.side_n = -15;
      meta.heel_moment_nm = -17;
      meta.controls = {{"gennaker_tack_ease_m", 0.02 * k}};
      const Mesh flying_mesh = cutAbove(generateSailMesh(flying), surface_top);
      importScan(db, meta, &doc, nullptr, {}, with_surface ? &flying_mesh : nullptr);
    }
  }

  TrimReportParams params(const std::string& out, const std::string& audience = "designer") const {
    TrimReportParams p;
    p.db_path = db_path;
    p.test = "tack ease";
    p.out_path = dir.file(out);
    p.audience = audience;
    return p;
  }
};

// Everything poppler prints on stderr while it reads the PDF.
std::string popplerComplaints(const std::string& pdf) {
  return run("pdftotext '" + pdf + "' /dev/null 2>&1; pdftoppm -r 20 '" + pdf + "' '" + pdf + ".warn' 2>&1");
}

struct Word {
  double x0, y0, x1, y1;
  std::string text;
};

// The words of page `page` (1-based) with their boxes, in points from the top-left.
std::vector<Word> pageWords(const std::string& pdf, int page) {
  const std::string html = run("pdftotext -bbox -f " + std::to_string(page) + " -l " + std::to_string(page) + " '" +
                               pdf + "' - 2>/dev/null");
  const std::regex word_re(
      R"re(<word xMin="([0-9.]+)" yMin="([0-9.]+)" xMax="([0-9.]+)" yMax="([0-9.]+)">([^<]*)</word>)re");
  std::vector<Word> words;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), word_re); it != std::sregex_iterator(); ++it)
    words.push_back({std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4]), (*it)[5]});
  return words;
}

std::string pageText(const std::string& pdf, int page) {
  return run("pdftotext -layout -f " + std::to_string(page) + " -l " + std::to_string(page) + " '" + pdf +
             "' - 2>/dev/null");
}

// The page whose text holds `title`; 0 when none does.
int pageWith(const std::string& pdf, const std::string& title) {
  for (int page = 1; page <= pdfPages(pdf); ++page)
    if (pageText(pdf, page).find(title) != std::string::npos) return page;
  return 0;
}

bool isCurveColour(const unsigned char* p) {
  const bool blue = p[2] > 120 && p[2] > p[0] + 60 && p[2] > p[1] + 40;
  const bool warm = p[0] > 90 && p[0] > p[1] + 50 && p[0] > p[2] + 50;  // step red and orange
  return blue || warm;
}

// Pixels of the curve colours in the page rectangle (points).
size_t curvePixels(const Raster& r, int dpi, double x0, double y0, double x1, double y1) {
  const double s = dpi / 72.0;
  size_t n = 0;
  for (int py = std::max(0, int(y0 * s)); py < std::min(r.height, int(y1 * s)); ++py)
    for (int px = std::max(0, int(x0 * s)); px < std::min(r.width, int(x1 * s)); ++px)
      n += isCurveColour(&r.rgb[(size_t(py) * r.width + px) * 3]);
  return n;
}

// The designer report of `t` written as `name`, and its page titled `title` rasterised at `dpi`.
struct ShownPage {
  std::string pdf;
  int page = 0;
  Raster raster;
};
ShownPage reportPage(const SmallTest& t, const std::string& name, const std::string& title, int dpi) {
  const TrimReportParams p = t.params(name);
  writeTrimReport(p);
  ShownPage shown{p.out_path, pageWith(p.out_path, title), {}};
  if (shown.page > 0) shown.raster = pageRaster(p.out_path, shown.page, dpi);
  return shown;
}

// Pairs of words on page `page` whose boxes overlap (by more than half a point), as "a / b".
std::vector<std::string> overprintedWords(const std::string& pdf, int page) {
  std::vector<std::string> out;
  const std::vector<Word> words = pageWords(pdf, page);
  for (size_t i = 0; i < words.size(); ++i)
    for (size_t j = i + 1; j < words.size(); ++j) {
      const Word &a = words[i], &b = words[j];
      if (a.x0 < b.x1 - 0.5 && b.x0 < a.x1 - 0.5 && a.y0 < b.y1 - 0.5 && b.y0 < a.y1 - 0.5)
        out.push_back("page " + std::to_string(page) + ": \"" + a.text + "\" overprints \"" + b.text + "\"");
    }
  return out;
}

TEST(ReportPictures, PopplerReadsTheFontsWithoutAWarning) {
  const TrimReportParams p = fixture().params("fonts.pdf");
  writeTrimReport(p);
  const std::string complaints = popplerComplaints(p.out_path);
  EXPECT_EQ(complaints, "") << "poppler: " << complaints.substr(0, 400);
  // The text still extracts character for character, beyond Latin-1 too.
  const std::string text = pdfText(p.out_path);
  for (const char* s : {"Grand-voile Été", "Øresund", "Lætitia", "Area, m²", "−", "±", "N·m"})
    EXPECT_NE(text.find(s), std::string::npos) << s;
}

// A design whose luff stands at x = 0 (the bow side, SPEC §2: +X forward) and whose
// clew is 4 m aft; the flying patch hugs the luff. Bow right from the side, bow up from above.
TEST(ReportPictures, TheSideViewShowsTheBowWhereItsCaptionSays) {
  Mesh design;
  design.vertices = {{0, 0, 0}, {0, 0, 10}, {-4, 0, 0}};
  design.triangles = {{0, 1, 2}};
  Mesh flying;
  flying.vertices = {{0, 0.05, 4}, {0, 1.0, 6}, {-1, 0.05, 4}, {-1, 1.0, 6}};  // leaning to leeward: seen from above too
  flying.triangles = {{0, 1, 3}, {0, 3, 2}};
  PrivateDisplay display;
  const SailViews v = renderSailViews(design, flying, std::vector<double>(4, 0.0));
  auto redCentroid = [](const RgbImage& img) {
    double sx = 0, sy = 0;
    size_t n = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const uint8_t* p = &img.rgb[(size_t(y) * img.width + x) * 3];
        if (p[0] > 120 && p[0] > 2 * p[1] && p[0] > 2 * p[2]) sx += x, sy += y, ++n;
      }
    return std::make_tuple(n ? sx / n / img.width : -1.0, n ? sy / n / img.height : -1.0, n);
  };
  const auto [side_x, side_y, side_n] = redCentroid(v.side);
  ASSERT_GT(side_n, 100u);
  // The 4 m design fills the middle of the tall picture; the patch's metre at the luff lies
  // right of its centre (0.75 of the picture's width; 0.25 with the bow on the left).
  EXPECT_GT(side_x, 0.65) << "the patch at the luff (forward) is drawn on the right of the side view";
  const auto [top_x, top_y, top_n] = redCentroid(v.top);
  ASSERT_GT(top_n, 10u);
  EXPECT_LT(top_y, 0.4) << "from above, the bow is up";

  const SmallTest t(SailType::Main, 1, true);
  const TrimReportParams p = t.params("caption.pdf");
  writeTrimReport(p);
  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find("bow to the right"), std::string::npos);
  EXPECT_EQ(text.find("(port), bow to the right"), std::string::npos) << "from port the bow is on the left";
}

// The demo's sections sit at 25–75 % of the height; the surface the analysis
// reconstructed covers the whole sail, and the report draws that.
TEST(ReportPictures, TheFlyingSurfaceIsTheScannedSailNotALoftBetweenSections) {
  const SmallTest stored(SailType::Main, 1, true);
  const TrimReportData with = prepareTrimReport(stored.params("unused.pdf"));
  ASSERT_EQ(with.steps.size(), 1u);
  EXPECT_FALSE(with.steps[0].lofted);
  auto zSpan = [](const Mesh& m) {
    double lo = 1e9, hi = -1e9;
    for (const Vec3& v : m.vertices) lo = std::min(lo, v.z()), hi = std::max(hi, v.z());
    return hi - lo;
  };
  const double design_height = zSpan(*with.data.design_mesh);
  // The generator's mesh of the flying shape spans the design's height (its twist
  // and camber move points sideways, not up).
  EXPECT_GT(zSpan(with.steps[0].flying_surface), 0.98 * design_height);
  // 1 % more camber everywhere: the mean deviation is a few cm at most on a 3 m chord, to leeward.
  EXPECT_GT(with.steps[0].deviation.mean_m, 0.0);
  EXPECT_LT(with.steps[0].deviation.max_abs_m, 0.1);

  const TrimReportParams p = stored.params("surface.pdf");
  writeTrimReport(p);
  EXPECT_NE(pdfText(p.out_path).find("reconstructed"), std::string::npos);
  EXPECT_EQ(pdfText(p.out_path).find("lofted"), std::string::npos);
  // The side view (page 2, the frame at 42, 58, 190 × 330 pt): the red surface reaches from the
  // foot to near the head of the design's blue grid; at the narrow head the grid drawn over
  // it hides it (the loft between 25 and 75 % would cover half the height).
  const int dpi = 72;
  const Raster r = pageRaster(p.out_path, 2, dpi);
  ASSERT_GT(r.width, 0);
  auto rows = [&](bool red) {
    int lo = 1 << 30, hi = -1;
    for (int y = 60; y < 386; ++y)
      for (int x = 44; x < 230; ++x) {
        const unsigned char* q = &r.rgb[(size_t(y) * r.width + x) * 3];
        const bool is = red ? (q[0] > 90 && q[0] > q[1] + 50 && q[0] > q[2] + 50)
                            : (q[2] > 120 && q[2] > q[0] + 60 && q[2] > q[1] + 40);
        if (is) lo = std::min(lo, y), hi = std::max(hi, y);
      }
    return std::make_pair(lo, hi);
  };
  const auto [blue_lo, blue_hi] = rows(false);
  const auto [red_lo, red_hi] = rows(true);
  ASSERT_GT(blue_hi, blue_lo);
  EXPECT_GT(red_hi - red_lo, 0.75 * (blue_hi - blue_lo)) << "red " << red_lo << "–" << red_hi << ", blue " << blue_lo
                                                        << "–" << blue_hi;

  // A scan stored with its sections only: the loft stands in, and the legend says so.
  const SmallTest sections_only(SailType::Main, 1, false);
  const TrimReportData without = prepareTrimReport(sections_only.params("unused.pdf"));
  EXPECT_TRUE(without.steps[0].lofted);
  EXPECT_LT(zSpan(without.steps[0].flying_surface), 0.6 * design_height);
  const TrimReportParams q = sections_only.params("lofted.pdf");
  writeTrimReport(q);
  EXPECT_NE(pdfText(q.out_path).find("lofted"), std::string::npos);
  EXPECT_NE(pdfText(q.out_path).find("not stored"), std::string::npos);
}

// The designer's report fits the design onto the last step's stored surface: the page "Where the
// design moved" shows each design point's move and the cloth's stretch, the part above the last
// samples (a scan that stopped at 80 % of the height) drawn pale as inferred.
TEST(ReportPictures, WhereTheDesignMovedFitsTheDesignAndTellsWhatWasInferred) {
  const SmallTest t(SailType::Main, 1, true, 1.0, {}, 0.8);
  const TrimReportData r = prepareTrimReport(t.params("unused.pdf"));
  ASSERT_TRUE(r.moved.has_value());
  const DesignMoved& m = *r.moved;
  const Mesh& design = *r.data.design_mesh;
  ASSERT_EQ(m.normal_m.size(), design.vertices.size());
  SailDesign flying = t.design;
  for (auto& s : flying.stations) s.camber_pct += 1.0;
  const DesignDistance truth(generateSailMesh(flying, 160, 80));
  double lo = 1e9, hi = -1e9;
  for (const Vec3& v : design.vertices) lo = std::min(lo, v.z()), hi = std::max(hi, v.z());
  // Below the cut (less a row of the design's mesh), the fit passes through the stored surface
  // (an exact surface: no noise) and no vertex is inferred; well above it, all are.
  double err2 = 0;
  size_t below = 0, below_inferred = 0, above = 0, above_inferred = 0;
  for (size_t v = 0; v < design.vertices.size(); ++v) {
    const double h = (design.vertices[v].z() - lo) / (hi - lo);
    if (h < 0.75) {
      ++below;
      below_inferred += m.inferred[v];
      const double d = truth.signedDistance(m.fit.fitted.vertices[v]);
      err2 += d * d;
    } else if (h > 0.85) {
      ++above;
      above_inferred += m.inferred[v];
    }
  }
  ASSERT_GT(below, 100u);
  ASSERT_GT(above, 10u);
  EXPECT_EQ(below_inferred, 0u);
  EXPECT_EQ(above_inferred, above);
  EXPECT_LT(std::sqrt(err2 / static_cast<double>(below)), 0.002);
  // One percent more camber: the move along the normal where scanned is to leeward, mm to cm.
  EXPECT_GT(m.normal_scanned.mean_m, 0.0);
  EXPECT_LT(m.normal_scanned.max_abs_m, 0.1);

  const TrimReportParams p = t.params("moved.pdf");
  writeTrimReport(p);
  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find("Where the design moved"), std::string::npos);
  EXPECT_NE(text.find("Stretch of the cloth"), std::string::npos);
  // The share drawn pale is the fit's own uncovered area.
  EXPECT_NE(text.find("(" + std::to_string(static_cast<int>(std::lround(100 * (1 - m.fit.coverage)))) + " % of the area)"),
            std::string::npos);
  // For the crew the page is left out.
  const TrimReportParams crew = t.params("crew.pdf", "crew");
  writeTrimReport(crew);
  EXPECT_EQ(pdfText(crew.out_path).find("Where the design moved"), std::string::npos);
}

// Step 1 flies the design, step 3 decimetres off it: every 3D page uses the one scale
// that holds the largest step's 5–95 % deviations.
TEST(ReportPictures, OneDeviationScaleForTheWholeReport) {
  const TrimReportParams p = fixture().params("scale.pdf");
  const TrimReport report = writeTrimReport(p);
  double widest = 0;
  for (const StepComparison& c : report.content.steps)
    widest = std::max({widest, std::abs(c.deviation.p5_m), std::abs(c.deviation.p95_m)});
  EXPECT_GE(report.deviation_range_m, widest);
  EXPECT_LT(report.deviation_range_m, 2.5 * widest) << "a round number just above it";
  const std::string end_label = "+" + fmt("%.0f", 1000 * report.deviation_range_m);
  for (int page = 2; page < 2 + kSteps; ++page) {
    const std::string text = pageText(p.out_path, page);
    ASSERT_NE(text.find("Deviation, mm"), std::string::npos) << "page " << page;
    EXPECT_NE(text.find(end_label), std::string::npos) << "page " << page << " scale ends at " << end_label;
  }
}

// A gennaker's sections are 20–25 % deep: drawn at twice their depth they would run
// through the legend and the page's title band.
TEST(ReportPictures, SectionShapesStayInsideTheirPanels) {
  const SmallTest t(SailType::Gennaker, 2, true, 4.0);
  const int dpi = 100;
  const ShownPage shown = reportPage(t, "curves.pdf", "Section shapes, flying over design", dpi);
  ASSERT_GT(shown.page, 0);
  const Raster& r = shown.raster;
  ASSERT_GT(r.width, 0);
  EXPECT_EQ(curvePixels(r, dpi, 0, 0, 595, 34), 0u) << "curves in the title band";
  size_t curves = curvePixels(r, dpi, 0, 34, 595, 800);
  EXPECT_GT(curves, 2000u) << "the curves are drawn";
  for (const Word& w : pageWords(shown.pdf, shown.page)) {
    if (w.y0 > 800) continue;  // the footer
    EXPECT_LT(curvePixels(r, dpi, w.x0 + 1, w.y0 + 1, w.x1 - 1, w.y1 - 1), 4u) << "a curve runs through \"" << w.text << "\"";
  }
}

// Sections at 25, 50 and 75 %: the height axis spans them, not 0–100 %.
TEST(ReportPictures, PlotsSpanTheMeasuredHeights) {
  const SmallTest t(SailType::Main, 1, true);
  const int dpi = 100;
  const ShownPage shown = reportPage(t, "plots.pdf", "Camber, draft and twist up the sail", dpi);
  ASSERT_GT(shown.page, 0);
  const Raster& r = shown.raster;
  ASSERT_GT(r.width, 0);
  // The camber plot's frame: from trim_report's layout (x 72–205 pt, y 98–478 pt); the red
  // flying line joins its three points.
  const double s = dpi / 72.0;
  int lo = 1 << 30, hi = -1;
  for (int y = int(98 * s); y < int(478 * s); ++y)
    for (int x = int(75 * s); x < int(205 * s); ++x) {
      const unsigned char* q = &r.rgb[(size_t(y) * r.width + x) * 3];
      if (q[0] > 150 && q[0] > q[1] + 80 && q[0] > q[2] + 80) lo = std::min(lo, y), hi = std::max(hi, y);
    }
  ASSERT_GT(hi, lo);
  EXPECT_GT((hi - lo) / (380 * s), 0.75) << "the data span " << (hi - lo) / s << " pt of the 380 pt plot";
  // Its height labels are the sections' heights.
  std::set<std::string> labels;
  for (const Word& w : pageWords(shown.pdf, shown.page))
    if (w.x1 < 72 && w.y0 > 90 && w.y1 < 490) labels.insert(w.text);
  EXPECT_EQ(labels, (std::set<std::string>{"25", "50", "75"}));
}

// The step table's headings keep to their columns, and the crew reads controls in words with units.
TEST(ReportPictures, StepTableHeadingsDoNotOverprintAndControlsReadInWords) {
  const SmallTest t(SailType::Main, 2, true);
  for (const std::string audience : {"designer", "crew"}) {
    SCOPED_TRACE(audience);
    const TrimReportParams p = t.params(audience + "-steps.pdf", audience);
    writeTrimReport(p);
    const std::string text = pdfText(p.out_path);
    EXPECT_EQ(text.find("gennaker_tack_ease_m"), std::string::npos);
    EXPECT_EQ(text.find('_'), std::string::npos) << "no snake_case name reaches the page";
    EXPECT_NE(text.find("gennaker tack ease 0 → 0.02 m"), std::string::npos);
    const int page = pageWith(p.out_path, "Trim steps: what changed");
    ASSERT_GT(page, 0);
    const std::vector<std::string> clashes = overprintedWords(p.out_path, page);
    EXPECT_TRUE(clashes.empty()) << clashes.front();
  }
}

// Nothing on any page of either audience's report, for a main of eight sections and a
// gennaker of three, is printed over anything else.
TEST(ReportPictures, NoWordOverprintsAnotherOnAnyPage) {
  const SmallTest gennaker(SailType::Gennaker, 3, true, 4.0);
  std::vector<TrimReportParams> reports = {fixture().params("all-designer.pdf"), gennaker.params("g-designer.pdf"),
                                           gennaker.params("g-crew.pdf", "crew")};
  TrimReportParams crew = fixture().params("all-crew.pdf");
  crew.audience = "crew";
  reports.push_back(crew);
  for (const TrimReportParams& p : reports) {
    SCOPED_TRACE(p.out_path);
    const TrimReport written = writeTrimReport(p);
    for (int page = 1; page <= written.pages; ++page) {
      const std::vector<std::string> clashes = overprintedWords(p.out_path, page);
      EXPECT_TRUE(clashes.empty()) << clashes.size() << " clashes, first " << clashes.front();
      for (const Word& w : pageWords(p.out_path, page))
        EXPECT_TRUE(w.x0 >= 0 && w.x1 <= 595.3 && w.y0 >= 0 && w.y1 <= 841.9) << "off the page: " << w.text;
    }
  }
}

// A luff sag within 2σ of zero was not found: it reads "none", and its height is no result.
TEST(ReportPictures, ASagTheScanDidNotResolveReadsNone) {
  const SmallTest t(SailType::Main, 1, true, 1.0, [](nlohmann::json& doc) {
    doc["luff"] = {{"lufa_sag_pct", 0.02}, {"lufa_position_pct", 12.0}, {"lusw_sag_pct", 0.9},
                   {"lusw_position_pct", 55.0}};
    doc["luff"]["uncertainty"] = {{"lufa_sag_pct", 0.03}, {"lufa_position_pct", 17.0}, {"lusw_sag_pct", 0.04},
                                  {"lusw_position_pct", 9.0}};
  });
  const TrimReportParams p = t.params("sag.pdf");
  writeTrimReport(p);
  std::istringstream text(pdfText(p.out_path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  auto lineAfter = [&](const std::string& label, int offset) {
    for (size_t i = 0; i + offset < lines.size(); ++i)
      if (lines[i].find(label) != std::string::npos) return lines[i + offset];
    return std::string();
  };
  const std::string lufa = lineAfter("Luff sag in the sail's plane", 0);
  EXPECT_NE(lufa.find("none (± 0.03)"), std::string::npos) << lufa;
  const std::string lufa_height = lineAfter("Luff sag in the sail's plane", 1);
  ASSERT_NE(lufa_height.find("its height up the luff"), std::string::npos) << lufa_height;
  EXPECT_EQ(lufa_height.find("12 ± 17"), std::string::npos) << lufa_height;
  const std::string lusw = lineAfter("Luff sag across it", 0);
  EXPECT_NE(lusw.find("0.90 ± 0.04"), std::string::npos) << "a sag of 22σ is a result: " << lusw;
  EXPECT_NE(lineAfter("Luff sag across it", 1).find("55 ± 9"), std::string::npos);
}

}  // namespace
}  // namespace sailshape
