// The PDF trim report built from a database with known values, read back with
// poppler's pdftotext / pdfinfo / pdftoppm.
#include <gtest/gtest.h>

#include <regex>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/core/errors.hpp"
#include "analysis/design/sail_generator.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "reports/pdf_document.hpp"
#include "reports/private_display.hpp"
#include "reports/render_views.hpp"
#include "reports/report_summary.hpp"
#include "reports/trim_report.hpp"
#include "tests/cli/run_sailshape.hpp"
#include "tests/database/db_fixture.hpp"
#include "tests/reports/report_fixture.hpp"

namespace sailshape {
namespace {

using test::TempDir;
using namespace report_test;

// CI has no display: every render here goes through the report's own Xvfb.
class NoDisplay : public ::testing::Environment {
 public:
  void SetUp() override { unsetenv("DISPLAY"); }
};
const auto* const kNoDisplay = ::testing::AddGlobalTestEnvironment(new NoDisplay);


TEST(TrimReport, DesignIsAnalysedAtTheFlyingFractions) {
  TrimReportParams p = fixture().params("unused.pdf");
  const TrimReportData r = prepareTrimReport(p);
  ASSERT_EQ(r.data.steps.size(), size_t(kSteps));
  ASSERT_EQ(r.design_sections.sections.size(), size_t(kSections));
  const SailSurface design(fixture().design);
  // Clean-data tolerances of the analysis core (tests/analysis/design/design_compare_test.cpp).
  for (const Section& s : r.design_sections.sections) {
    SCOPED_TRACE("fraction " + std::to_string(s.fraction));
    const KnownSection k = design.section(s.fraction);
    EXPECT_NEAR(s.value.camber_pct, k.camber_pct, 0.1);
    EXPECT_NEAR(s.value.draft_pct, k.draft_pct, 1.0);
    EXPECT_NEAR(s.value.twist_deg, k.twist_deg, 0.1);
    EXPECT_NEAR(s.value.entry_deg, k.entry_deg, 1.0);
    EXPECT_NEAR(s.value.exit_deg, k.exit_deg, 1.0);
  }
  // Step 3 is 3° + 3°·f more twisted and 1 % deeper than the design everywhere.
  for (const ComparedSection& c : r.steps.back().sections) {
    EXPECT_NEAR(c.flying.twist_deg - c.design.twist_deg, 3.0 * (1 + c.fraction), 0.2);
    EXPECT_NEAR(c.flying.camber_pct - c.design.camber_pct, 1.0, 0.15);
  }
  // The first step flies the design itself: its lofted surface is on the design
  // within the loft's chordwise interpolation (a few mm on 1.1 m between sections).
  EXPECT_LT(std::abs(r.steps.front().deviation.mean_m), 0.005);
  EXPECT_LT(r.steps.front().deviation.max_abs_m, 0.02);
  EXPECT_GT(r.steps.back().deviation.max_abs_m, 0.05);  // 6° more twist at the head moves the leech by decimetres
  ASSERT_FALSE(r.summary.sentences.empty());
  EXPECT_NE(r.summary.sentences.front().find("The head section"), std::string::npos) << r.summary.sentences.front();
  EXPECT_NE(r.summary.sentences.front().find("more twisted than designed"), std::string::npos);
}

TEST(TrimReport, DesignerReportShowsTheDatabaseNumbersAndBothColours) {
  const TrimReportParams p = fixture().params("designer.pdf");
  const TrimReport report = writeTrimReport(p);
  EXPECT_TRUE(report.private_display);
  // Cover, 3 × (3D page, section table), plots, section curves, step changes.
  EXPECT_EQ(report.pages, 1 + 2 * kSteps + 3);
  EXPECT_EQ(pdfPages(p.out_path), report.pages);

  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find(kSail), std::string::npos);
  EXPECT_NE(text.find(kBoat), std::string::npos);
  // Page titles and the sail and boat share the header band without running into each other.
  const std::vector<std::string> clashes = overlappingHeaderWords(p.out_path);
  EXPECT_TRUE(clashes.empty()) << clashes.size() << " overlapping header words, first " << clashes.front();
  EXPECT_NE(text.find(kCampaign), std::string::npos);
  EXPECT_NE(text.find("Voilerie Lætitia"), std::string::npos);
  for (int k = 0; k < kSteps; ++k)
    for (const auto& s : fixture().docs[k]["sections"]) {
      const double f = s["fraction"];
      SCOPED_TRACE("step " + std::to_string(k + 1) + " fraction " + std::to_string(f));
      const auto& u = s["uncertainty"];
      EXPECT_NE(text.find(fmt("%.2f", s["camber_pct"].get<double>()) + " ± " + fmt("%.2f", u["camber_pct"].get<double>())),
                std::string::npos);
      EXPECT_NE(text.find(fmt("%.1f", s["draft_pct"].get<double>()) + " ± 0.9"), std::string::npos);
      EXPECT_NE(text.find(fmt("%.1f", s["twist_deg"].get<double>()) + " ± 0.2"), std::string::npos);
      EXPECT_NE(text.find(fmt("%.1f", s["entry_deg"].get<double>()) + " ± 1.1"), std::string::npos);
      EXPECT_NE(text.find(fmt("%.1f", s["exit_deg"].get<double>()) + " ± 1.3"), std::string::npos);
    }
  // Forces and controls of the step table.
  for (const char* v : {"410", "435", "460", "980", "940", "900", "1.25", "1.2", "1.15"})
    EXPECT_NE(text.find(v), std::string::npos) << v;
  EXPECT_NE(text.find("more twisted than designed"), std::string::npos);

  // The 3D page of every step: each shape view (side, astern, top) shows the
  // design's blue grid and the flying red surface; the deviation map is not blank.
  const int dpi = 72;
  // From astern and above the sail is seen edge-on and the grid drawn over
  // the surface may hide it: the flying red is required from the side.
  struct Frame { float x, y, w, h; bool blue, red; };
  const Frame frames[] = {{42, 58, 190, 330, true, true},        // side
                          {252.5f, 58, 90, 330, true, false},    // astern
                          {363, 58, 190, 330, false, false},     // deviation
                          {42, 422, 250, 190, true, false}};     // top
  for (int page = 2; page < 2 + kSteps; ++page) {
    SCOPED_TRACE("page " + std::to_string(page));
    const Raster r = pageRaster(p.out_path, page, dpi);
    ASSERT_GT(r.width, 0);
    for (const Frame& f : frames) {
      const Colours c = countColours(r, dpi, f.x + 2, f.y + 2, f.w - 4, f.h - 4);
      SCOPED_TRACE("view at " + std::to_string(f.x) + ", " + std::to_string(f.y));
      EXPECT_GT(c.ink, c.pixels / 40);
      if (f.blue) {
        EXPECT_GT(c.blue, c.pixels / 100);
      }
      if (f.red) {
        EXPECT_GT(c.red, c.pixels / 20);
      }
    }
  }
}

// The outline block of each step's table page: the stored flying outline, the
// design's from analysing its mesh, and their difference, each ± 1σ.
TEST(TrimReport, OutlineShowsStoredFlyingAndAnalysedDesignLengths) {
  const TrimReportParams p = fixture().params("outline.pdf");
  const TrimReport report = writeTrimReport(p);
  const TrimReportData& r = report.content;
  // The design's edges and area against the generator's exact surface: an 80 × 40
  // mesh of it follows the edges to well under a millimetre; its corners are found
  // to a few (tests/analysis/design/design_compare_test.cpp), which moves a length by as much.
  const SailSurface exact(fixture().design);
  auto arc = [&](auto point) {
    double length = 0;
    for (int i = 1; i <= 2000; ++i) length += (point(i / 2000.0) - point((i - 1) / 2000.0)).norm();
    return length;
  };
  const double luff = arc([&](double f) { return exact.at(f, 0.0); });
  const double leech = arc([&](double f) { return exact.at(f, 1.0); });
  const double foot = arc([&](double u) { return exact.at(0.0, u); });
  double area = 0;
  constexpr int kN = 400;
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const double f = (i + 0.5) / kN, u = (j + 0.5) / kN, h = 0.5 / kN;
      area += ((exact.at(f + h, u) - exact.at(f - h, u)).cross(exact.at(f, u + h) - exact.at(f, u - h))).norm();
    }
  EXPECT_NEAR(r.design_outline.luff_length_m.value, luff, 0.005);
  EXPECT_NEAR(r.design_outline.leech_length_m.value, leech, 0.005);
  EXPECT_NEAR(r.design_outline.foot_length_m.value, foot, 0.005);
  EXPECT_NEAR(r.design_outline.area_m2.value, area, 0.02);
  EXPECT_TRUE(std::isnan(r.design_outline.top_length_m.value));  // a triangular main has no top edge
  EXPECT_TRUE(std::isfinite(r.design_outline.luff_length_m.sigma));

  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find("Luff length, m"), std::string::npos);
  EXPECT_EQ(text.find("Top length"), std::string::npos);
  for (int k = 0; k < kSteps; ++k) {
    SCOPED_TRACE("step " + std::to_string(k + 1));
    const nlohmann::json& doc = fixture().docs[k];
    const ReportOutline& o = r.data.steps[k].outline;
    EXPECT_DOUBLE_EQ(o.luff_length_m.value, doc["sail"]["luff_length_m"].get<double>());
    EXPECT_DOUBLE_EQ(o.area_m2.sigma, 0.02);
    EXPECT_DOUBLE_EQ(o.lufa_sag_pct.value, doc["luff"]["lufa_sag_pct"].get<double>());
    EXPECT_DOUBLE_EQ(o.lusw_position_pct.sigma, 9.0);
    EXPECT_DOUBLE_EQ(o.beam_footprint_m, 0.021 + 0.01 * k);
    EXPECT_NE(text.find("moved out " + fmt("%.1f", 2.1 + k) + " cm for the scanner"), std::string::npos) << k;
    const double dl = o.luff_length_m.value - r.design_outline.luff_length_m.value;
    const double dl_sigma = std::hypot(o.luff_length_m.sigma, r.design_outline.luff_length_m.sigma);
    EXPECT_NE(text.find(fmt("%.3f", o.luff_length_m.value) + " ± 0.004"), std::string::npos);
    EXPECT_NE(text.find(fmt("%.2f", o.area_m2.value) + " ± 0.02"), std::string::npos);
    EXPECT_NE(text.find(fmt("%.2f", o.lufa_sag_pct.value) + " ± 0.03"), std::string::npos);
    const std::string signed_dl = (dl < 0 ? "−" + fmt("%.3f", -dl) : fmt("%+.3f", dl)) + " ± " + fmt("%.3f", dl_sigma);
    EXPECT_NE(text.find(signed_dl), std::string::npos) << signed_dl;
  }
}

// An analysis stored without its outline (imported from a document with sections
// only) shows "–" for flying, and the design's values still.
TEST(TrimReport, AnAnalysisWithoutItsOutlineShowsDashes) {
  TempDir dir;
  const std::string db_path = dir.file("no-outline.sailshape");
  {
    Database db = openSailDatabase(db_path);
    const Mesh mesh = generateSailMesh(fixture().design);
    upsertSail(db, {kSail, "mainsail", "M", "", "", kBoat}, &mesh);
    nlohmann::json doc = fixture().docs.front();
    doc.erase("sail");
    doc.erase("luff");
    ImportMetadata meta;
    meta.campaign = kCampaign;
    meta.session = "day 1";
    meta.sail = kSail;
    meta.test = kTest;
    meta.trim_step = 1;
    importScan(db, meta, &doc);
  }
  TrimReportParams p;
  p.db_path = db_path;
  p.test = kTest;
  p.out_path = dir.file("no-outline.pdf");
  const TrimReport report = writeTrimReport(p);
  EXPECT_TRUE(std::isnan(report.content.data.steps.front().outline.luff_length_m.value));
  EXPECT_EQ(report.content.data.steps.front().outline.beam_footprint_m, 0.0);
  const std::string text = pdfText(p.out_path);
  const size_t at = text.find("Luff length, m");
  ASSERT_NE(at, std::string::npos);
  const std::string line = text.substr(at, text.find('\n', at) - at);
  EXPECT_NE(line.find(fmt("%.3f", report.content.design_outline.luff_length_m.value)), std::string::npos) << line;
  EXPECT_NE(line.find("–"), std::string::npos) << line;
}

TEST(TrimReport, CrewReportIsShorterAndInPlainWords) {
  TrimReportParams p = fixture().params("crew.pdf");
  p.audience = "crew";
  const TrimReport report = writeTrimReport(p);
  EXPECT_EQ(report.pages, 4);  // cover, 3D views of the last step, plots, step changes
  EXPECT_EQ(pdfPages(p.out_path), 4);
  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find("How the sail flew"), std::string::npos);
  EXPECT_NE(text.find("on average"), std::string::npos);
  EXPECT_NE(text.find("sheet 1.25 → 1.2"), std::string::npos);
  // No uncertainties in the crew's numbers ("12.3 ± 0.4"); the units note may still explain ±.
  for (size_t at = text.find(" ± "); at != std::string::npos; at = text.find(" ± ", at + 1))
    EXPECT_FALSE(at > 0 && std::isdigit(static_cast<unsigned char>(text[at - 1]))) << text.substr(at - 10, 20);
}

TEST(TrimReport, SingleScanReport) {
  TrimReportParams p = fixture().params("scan.pdf");
  p.test.clear();
  p.scan_id = fixture().scan_ids[1];
  const TrimReport report = writeTrimReport(p);
  EXPECT_EQ(report.pages, 5);  // cover, 3D, table, plots, curves
  EXPECT_EQ(pdfPages(p.out_path), 5);
  const std::string text = pdfText(p.out_path);
  const auto& s = fixture().docs[1]["sections"][7];
  EXPECT_NE(text.find(fmt("%.1f", s["twist_deg"].get<double>()) + " ± 0.2"), std::string::npos);
  EXPECT_EQ(text.find("what changed"), std::string::npos);
  EXPECT_NE(text.find(std::string(kTest) + " · trim step 2"), std::string::npos);
}

TEST(TrimReport, ASectionTheAnalysisCouldNotMeasureIsNamedWithWhy) {
  TempDir dir;
  const std::string db_path = dir.file("partial.sailshape");
  int64_t scan_id = 0;
  {
    Database db = openSailDatabase(db_path);
    const SailDesign design = exampleDesign(SailType::Main);
    const Mesh mesh = generateSailMesh(design);
    upsertSail(db, {"J2", "jib", "", "", "", ""}, &mesh);
    const SailSurface surface(design);
    nlohmann::json doc;
    doc["sections"] = {flyingSection(surface, 0.25, 0), flyingSection(surface, 0.75, 0)};
    doc["unmeasured_sections"] = {
        {{"fraction", 0.5}, {"reason", "the section plane at fraction 0.500 crosses a hole 44 % of the chord wide"}}};
    ImportMetadata meta;
    meta.campaign = "Partial";
    meta.sail = "J2";
    scan_id = importScan(db, meta, &doc).scan_id;
  }
  TrimReportParams p;
  p.db_path = db_path;
  p.scan_id = scan_id;
  p.out_path = dir.file("partial.pdf");
  writeTrimReport(p);
  const std::string text = pdfText(p.out_path);
  EXPECT_NE(text.find("The 50 % section was not measured"), std::string::npos) << text;
  EXPECT_NE(text.find("crosses a hole 44 %"), std::string::npos) << text;
  // Named on the summary too (a bullet there, a note under the section table).
  size_t named = 0;
  for (size_t at = text.find("section was not measured"); at != std::string::npos;
       at = text.find("section was not measured", at + 1))
    ++named;
  EXPECT_EQ(named, 2u) << text;
  EXPECT_EQ(text.find("Every section flew within"), std::string::npos) << text;

  // One measured section makes no flying surface: one error naming the scan and what is missing.
  {
    Database db = openSailDatabase(db_path);
    const SailSurface surface(exampleDesign(SailType::Main));
    nlohmann::json doc;
    doc["sections"] = {flyingSection(surface, 0.5, 0)};
    doc["unmeasured_sections"] = {{{"fraction", 0.25}, {"reason", "leaves 14 % of the chord at the leech uncovered"}},
                                  {{"fraction", 0.75}, {"reason", "crosses a hole"}}};
    ImportMetadata meta;
    meta.campaign = "Partial";
    meta.sail = "J2";
    p.scan_id = importScan(db, meta, &doc).scan_id;
  }
  p.out_path = dir.file("one.pdf");
  try {
    writeTrimReport(p);
    ADD_FAILURE() << "a report of one section";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("has 1 measured section (not measured: 25 %, 75 %)"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(p.out_path));
}

TEST(TrimReport, BadRequestsThrowAndLeaveAnExistingFileAlone) {
  const std::string keep = fixture().dir.file("keep.pdf");
  { std::ofstream(keep) << "an earlier report"; }
  TrimReportParams p = fixture().params("keep.pdf");
  p.test.clear();
  p.scan_id = 999;
  EXPECT_THROW(writeTrimReport(p), InvalidInput);  // unknown scan
  EXPECT_EQ(test::readBytes(keep), "an earlier report");
  p = fixture().params("x.pdf");
  p.test = "no such test";
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  p = fixture().params("x.pdf");
  p.db_path = fixture().dir.file("missing.sailshape");
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  EXPECT_FALSE(std::filesystem::exists(p.db_path));
  p = fixture().params("x.pdf");
  p.out_path = fixture().dir.file("no/such/folder/x.pdf");
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  p.out_path = fixture().dir.file("");
  EXPECT_THROW(writeTrimReport(p), InvalidInput);  // a directory
  p = fixture().params("x.pdf");
  p.audience = "owner";
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  p = fixture().params("x.pdf");
  p.scan_id = fixture().scan_ids[0];  // and a test
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  p = fixture().params("x.pdf");
  p.test.clear();
  EXPECT_THROW(writeTrimReport(p), InvalidInput);
  p = fixture().params("x.pdf");
  p.fonts.regular = fixture().dir.file("no-font.ttf");
  EXPECT_THROW(writeTrimReport(p), PdfError);
  EXPECT_FALSE(std::filesystem::exists(p.out_path));
}

TEST(TrimReport, SailWithoutDesignAndScanWithoutAnalysisAreRefused) {
  TempDir dir;
  const std::string db_path = dir.file("nodesign.sailshape");
  int64_t analysed = 0, bare = 0;
  {
    Database db = openSailDatabase(db_path);
    nlohmann::json doc = test::analysisDoc(10.0);
    ImportMetadata meta;
    meta.sail = "plain";
    analysed = importScan(db, meta, &doc).scan_id;
    Cloud cloud;
    cloud.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};
    meta.trim_step = 1;
    bare = importScan(db, meta, nullptr, &cloud).scan_id;
  }
  TrimReportParams p;
  p.db_path = db_path;
  p.out_path = dir.file("x.pdf");
  p.scan_id = analysed;
  EXPECT_THROW(prepareTrimReport(p), InvalidInput);  // no design mesh
  p.scan_id = bare;
  EXPECT_THROW(prepareTrimReport(p), InvalidInput);  // no analysis
  const std::string foreign = dir.file("foreign.txt");
  { std::ofstream(foreign) << "not a database at all, just some text that is long enough"; }
  p.db_path = foreign;
  EXPECT_THROW(prepareTrimReport(p), DatabaseError);
}

TEST(PrivateDisplay, StartsXvfbWithoutDisplayAndStopsIt) {
  ASSERT_EQ(std::getenv("DISPLAY"), nullptr);
  {
    PrivateDisplay display;
    EXPECT_TRUE(display.started());
    ASSERT_NE(std::getenv("DISPLAY"), nullptr);
    EXPECT_EQ(display.display(), std::getenv("DISPLAY"));
    EXPECT_EQ(display.display()[0], ':');
    PrivateDisplay reuse;  // a display that opens is used as it is
    EXPECT_FALSE(reuse.started());
    EXPECT_EQ(reuse.display(), display.display());
  }
  EXPECT_EQ(std::getenv("DISPLAY"), nullptr);
}

TEST(PrivateDisplay, ReplacesADisplayThatDoesNotOpenAndRestoresIt) {
  setenv("DISPLAY", ":987", 1);  // no X server there
  ASSERT_FALSE(displayOpens(":987"));
  {
    PrivateDisplay display;
    EXPECT_TRUE(display.started());
    EXPECT_NE(display.display(), ":987");
    EXPECT_TRUE(displayOpens(display.display()));
  }
  ASSERT_NE(std::getenv("DISPLAY"), nullptr);
  EXPECT_STREQ(std::getenv("DISPLAY"), ":987");
  unsetenv("DISPLAY");
}

TEST(PrivateDisplay, FailsWithOneClearLineWhenXvfbIsMissing) {
  TempDir empty;
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", empty.file("").c_str(), 1);
  try {
    PrivateDisplay display;
    ADD_FAILURE() << "no exception";
  } catch (const DisplayError& e) {
    EXPECT_NE(std::string(e.what()).find("Xvfb is not installed"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  setenv("PATH", path.c_str(), 1);
}

TEST(ReportParts, BadInputsThrow) {
  EXPECT_THROW(loftSections({}), InvalidInput);
  ReportSection one;
  one.curve = {Vec3(0, 0, 1), Vec3(1, 0, 1)};
  EXPECT_THROW(loftSections({one}), InvalidInput);
  EXPECT_THROW(loftSections({one, one}, 1), InvalidInput);
  const Mesh mesh = generateSailMesh(exampleDesign(SailType::Main), 10, 6);
  EXPECT_THROW(renderSailViews(Mesh{}, mesh, std::vector<double>(mesh.vertices.size())), InvalidInput);
  EXPECT_THROW(renderSailViews(mesh, mesh, {1.0}), InvalidInput);
  RenderParams tiny;
  tiny.top.width_px = 2;
  EXPECT_THROW(renderSailViews(mesh, mesh, std::vector<double>(mesh.vertices.size()), tiny), InvalidInput);
  PdfFonts bad;
  bad.bold = "/nonexistent/font.ttf";
  EXPECT_THROW(PdfDocument{bad}, PdfError);
  PdfDocument pdf;
  EXPECT_THROW(pdf.text(0, 0, "x", 10), PdfError);  // before a page
  pdf.addPage();
  RgbImage broken;
  broken.width = 4;
  broken.height = 4;
  EXPECT_THROW(pdf.image(broken, 0, 0, 10, 10), PdfError);
  TempDir dir;
  EXPECT_THROW(pdf.save(dir.file("missing/x.pdf")), PdfError);
  SummaryParams negative;
  negative.twist_deg = -1;
  EXPECT_THROW(summarizeDifferences({}, negative), InvalidInput);
}

TEST(ReportParts, LoftPassesThroughTheSectionCurves) {
  ReportSection a, b;
  for (int i = 0; i <= 10; ++i) {
    a.curve.push_back(Vec3(i * 0.3, 0.1 * std::sin(i * 0.314), 1.0));
    b.curve.push_back(Vec3(i * 0.2, 0.08 * std::sin(i * 0.314), 3.0));
  }
  const Mesh m = loftSections({a, b}, 11, 3);
  ASSERT_EQ(m.vertices.size(), 5u * 11u);
  EXPECT_EQ(m.triangles.size(), 4u * 10u * 2u);
  for (int i = 0; i <= 10; ++i) {
    EXPECT_NEAR((m.vertices[i] - a.curve[i]).norm(), 0, 0.02);  // arc-length resampling of a gentle curve
    EXPECT_NEAR((m.vertices[4 * 11 + i] - b.curve[i]).norm(), 0, 0.02);
  }
  EXPECT_NEAR(m.vertices[2 * 11].z(), 2.0, 1e-12);
}

TEST(ReportParts, GridEdgesDropQuadDiagonals) {
  // A 3 × 2 grid of unit squares, each split along a diagonal: 17 grid edges, no diagonal.
  Mesh m;
  for (int r = 0; r <= 2; ++r)
    for (int c = 0; c <= 3; ++c) m.vertices.push_back(Vec3(c, 0, r));
  for (uint32_t r = 0; r < 2; ++r)
    for (uint32_t c = 0; c < 3; ++c) {
      const uint32_t a = r * 4 + c;
      m.triangles.push_back({a, a + 1, a + 5});
      m.triangles.push_back({a, a + 5, a + 4});
    }
  const auto edges = gridEdges(m);
  EXPECT_EQ(edges.size(), 17u);
  for (const auto& e : edges) EXPECT_NEAR((m.vertices[e[0]] - m.vertices[e[1]]).norm(), 1.0, 1e-12);
}

TEST(ReportSummary, NamesHeightsAndWordsTheLargestDifferences) {
  EXPECT_EQ(heightName(0.1), "foot");
  EXPECT_EQ(heightName(0.5), "middle");
  EXPECT_EQ(heightName(0.9), "head");
  const auto names = sectionNames({0.25, 0.5, 0.75});
  EXPECT_EQ(names[0], "the lower section");
  EXPECT_EQ(names[2], "the upper section");
  EXPECT_EQ(sectionNames({0.85, 0.9})[1], "the head section at 90 % height");

  ComparedSection head;
  head.fraction = 0.85;
  head.design = {3.0, 10.0, 45.0, 20.0, 0, 20.0, 10.0};
  head.flying = {3.0, 10.3, 47.0, 24.1, 0, 20.5, 6.0};
  head.design_u = {0.001, 0.05, 0.5, 0.05, 0, 0.5, 0.5};
  head.flying_u = {0.006, 0.15, 0.9, 0.2, 0, 1.0, 1.2};
  const Summary s = summarizeDifferences({head});
  ASSERT_EQ(s.sentences.size(), 2u);  // twist 4.1° and exit 4.0°; camber 0.3 % and draft 2 % (< 2σ) are not worth a word
  EXPECT_EQ(s.sentences[0], "The head section is 4.1° more twisted than designed.");
  EXPECT_EQ(s.sentences[1], "The head section has a leech 4.0° more open than designed.");
  EXPECT_FALSE(s.within_design);
  head.flying = head.design;
  EXPECT_TRUE(summarizeDifferences({head}).within_design);
}

TEST(ReportCli, ExitCodesAndOneLineErrors) {
  const std::filesystem::path dir = fixture().dir.file("");
  auto r = testing::runSailshape(dir, "report --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--db", "--scan", "--test", "--out", "--audience", "crew", "designer"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  const std::string out = fixture().dir.file("cli.pdf");
  r = testing::runSailshape(dir, "report -q --db '" + fixture().db_path + "' --scan 999 --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no scan with id 999"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  r = testing::runSailshape(dir, "report -q --db '" + fixture().dir.file("missing.db") + "' --scan 1 --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  r = testing::runSailshape(dir, "report -q --db '" + fixture().db_path + "' --scan 1 --out /nonexistent-dir/x.pdf");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
  r = testing::runSailshape(dir, "report --db '" + fixture().db_path + "' --scan 1 --test x --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 2);  // CLI11: --scan excludes --test
  r = testing::runSailshape(dir, "report --db '" + fixture().db_path + "' --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 1);
  r = testing::runSailshape(dir, "report --db '" + fixture().db_path + "' --scan 1 --audience owner --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(out));
  r = testing::runSailshape(dir, "report -q --db '" + fixture().db_path + "' --test '" + kTest + "' --audience crew --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(pdfPages(out), 4);
}

}  // namespace
}  // namespace sailshape
