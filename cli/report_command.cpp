// `sailshape report`: a PDF trim report of a scan or a test from the database.
#include <cstdio>
#include <memory>

#include "analysis/core/errors.hpp"
#include "cli/commands.hpp"
#include "cli/progress_bar.hpp"
#include "reports/trim_report.hpp"

namespace sailshape::cli {
namespace {

struct ReportOptions {
  TrimReportParams params;
  int64_t scan_id = 0;
  bool quiet = false;
};

void run(ReportOptions& o) {
  if (o.scan_id > 0) o.params.scan_id = o.scan_id;
  ProgressBar bar(!o.quiet);
  const TrimReport report = writeTrimReport(o.params, bar.progress());
  bar.finish();
  for (const auto& w : report.content.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!o.quiet)
    std::fprintf(stderr, "wrote %s (%d pages, %s)\n", report.out_path.c_str(), report.pages,
                 o.params.audience.c_str());
}

}  // namespace

void addReportCommand(CLI::App& app) {
  auto opt = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Write a PDF trim report of one scan or of a test's trim steps from the database\n\n"
      "Write a PDF trim report of one scan or of a test's trim steps from the database: a cover with boat, sail, "
      "campaign, conditions and units; 3D views of the design (blue grid) and the flying shape (red) from the side, "
      "above and astern with the signed deviation as a colour map in mm; the section table (camber, draft, twist, "
      "entry, exit: design, flying, difference, each ±1σ) and the outline table (luff, leech, foot and top lengths, "
      "area, the luff curve's sags: the same three rows); camber, draft and twist against height; each section's "
      "curve flying over design; for a test, the change of every parameter from step to step beside the measured "
      "forces; and a plain-words summary of the largest differences. The design's sections and outline come from "
      "analysing the sail's stored design mesh, its sections at the flying sections' heights. Renders offscreen: "
      "without DISPLAY a private Xvfb is started for the pictures.");
  cmd->add_option("--db", opt->params.db_path, "The sailshape database (see `sailshape db`); opened read-only")
      ->required();
  auto* scan = cmd->add_option("--scan", opt->scan_id, "Report on this scan (id as listed by `sailshape db list`)")
                   ->check(CLI::PositiveNumber);
  auto* test = cmd->add_option("--test", opt->params.test,
                               "Report on every trim step of this test (its name, as given to `sailshape db import "
                               "--test`), the latest analysed scan of each step");
  scan->excludes(test);
  test->excludes(scan);
  cmd->add_option("--sail", opt->params.sail, "With --test: the sail, when the test name is used for several sails");
  cmd->add_option("--out", opt->params.out_path,
                  "The PDF to write; an existing file is replaced only once the new report is complete")
      ->required();
  cmd->add_option("--audience", opt->params.audience,
                  "crew: fewer pages in plain words (cover and summary, 3D views of the last step, plots, step "
                  "changes in words); designer: every number (per step 3D views and section table with ±, plots, "
                  "section curves, step-to-step change table)")
      ->check(CLI::IsMember({"crew", "designer"}))
      ->capture_default_str();
  cmd->add_option("--font", opt->params.fonts.regular, "TrueType font embedded for text (UTF-8: accents print)")
      ->capture_default_str();
  cmd->add_option("--bold-font", opt->params.fonts.bold, "TrueType font embedded for headings")->capture_default_str();
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress output");
  cmd->callback([opt] {
    if (opt->scan_id <= 0 && opt->params.test.empty())
      throw InvalidInput("report: give --scan ID or --test NAME");
    run(*opt);
  });
}

}  // namespace sailshape::cli
