#pragma once
// `sailshape report`: a PDF trim report of one scan or of a test's trim steps,
// for the crew (few pages, plain words) or the designer (every number).
//
// Where the design's numbers come from: the database stores the sail's design
// as a mesh (sails.design_mesh), not as sections, so the design is analysed
// here with the analysis library at the fractions the flying sections were
// cut at (analyzeMeshSections, as `sailshape compare` does), and the two are
// compared section by section. The design's ± is that analysis's own
// uncertainty with no sensor noise (a resampled exact surface).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/progress.hpp"
#include "analysis/design/design_compare.hpp"
#include "analysis/fit/design_fit.hpp"
#include "reports/pdf_document.hpp"
#include "reports/render_views.hpp"
#include "reports/report_data.hpp"
#include "reports/report_summary.hpp"

namespace sailshape {

struct TrimReportParams {
  std::string db_path;
  std::optional<int64_t> scan_id;   // exactly one of scan_id and test
  std::string test;
  std::string sail;                 // picks the sail when a test name is used for several
  std::string out_path;             // the PDF
  std::string audience = "designer";  // "crew" or "designer"
  PdfFonts fonts;
  RenderParams render;
  // How the design mesh is sampled for its outline and sections: as `sailshape
  // compare` does (design_compare.hpp MeshSampling), so both give the same numbers.
  MeshSampling design_sampling;
  SummaryParams summary;
  int busy_timeout_ms = 5000;
};

// Design against flying at the flying sections' fractions, per trim step.
struct StepComparison {
  std::vector<ComparedSection> sections;  // by fraction
  Mesh flying_surface;                    // the analysis's reconstructed surface, or lofted through the section curves
  bool lofted = false;                    // the analysis stored no surface: the loft stands in for it
  std::vector<double> deviation_m;        // per flying_surface vertex, signed, + to leeward
  DistanceStats deviation;
};

// Where the design moved (issue 37): the design fitted onto the last step's stored surface,
// each design vertex's move along the design's normal (+ to leeward), along the sail (the
// move's part in the design's tangent plane) and the cloth's stretch there (the mean length
// change of its edges, %), and whether samples held it or the fit carried it on from around.
struct DesignMoved {
  DesignFit fit;
  std::vector<double> normal_m, along_m, stretch_pct;  // per design vertex
  std::vector<char> inferred;                           // per design vertex: no sample within the support radius
  DistanceStats normal_scanned, normal_inferred, along_scanned;
  double inferred_sigma_p50_m = 0;
};

struct TrimReportData {
  ReportData data;
  SectionAnalysis design_sections;  // the design analysed at every fraction any step was cut at
  ReportOutline design_outline;     // the design's outline and luff curve, from the same analysis
  std::vector<StepComparison> steps;
  Summary summary;                  // of the last step
  std::vector<std::string> warnings;
  std::vector<std::string> notes;   // how the design was analysed (e.g. resampled)
  // The last step's, when it stored its surface (the fit needs the scan's own shape, not a loft).
  std::optional<DesignMoved> moved;
};

// Loads and compares without writing anything. Throws InvalidInput for bad
// parameters or unknown ids, DatabaseError for a missing or foreign file.
TrimReportData prepareTrimReport(const TrimReportParams& params, const Progress& progress = {});

struct TrimReport {
  std::string out_path;
  int pages = 0;
  bool private_display = false;  // an Xvfb was started for the renders
  double deviation_range_m = 0;  // the ± limit of the report's one deviation colour scale
  TrimReportData content;
};

// Writes the PDF (an existing file is replaced only once the new one is
// complete). Throws InvalidInput for bad parameters or an output that cannot be
// written, plus what prepareTrimReport, PrivateDisplay and the PDF writer throw.
TrimReport writeTrimReport(const TrimReportParams& params, const Progress& progress = {});

// The flying surface through a scan's section curves (each resampled to
// `columns` points by arc length; `rows_between` rows interpolated between
// neighbouring sections). Throws InvalidInput for fewer than two curves.
Mesh loftSections(const std::vector<ReportSection>& sections, int columns = 41, int rows_between = 3);

}  // namespace sailshape
