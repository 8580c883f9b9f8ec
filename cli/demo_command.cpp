// `sailshape demo`: the whole product on its built-in emulated hardware.
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli/commands.hpp"
#include "cli/demo_session.hpp"
#include "cli/progress_bar.hpp"

namespace sailshape::cli {
namespace {

namespace fs = std::filesystem;

struct DemoCommandOptions {
  DemoOptions demo;
  bool quiet = false;
};

// The viewer as this build made it (beside this binary's folder: build/cli/sailshape and
// build/viewer/sailshape-viewer), relative to the working folder when it lies below it;
// where it is not there, the path README's build gives it.
std::string viewerPath() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path built = self.parent_path().parent_path() / "viewer" / "sailshape-viewer";
  if (ec || !fs::exists(built, ec)) return "build/viewer/sailshape-viewer";
  const fs::path relative = built.lexically_relative(fs::current_path(ec));
  if (!ec && !relative.empty() && *relative.begin() != "..") return relative.string();
  return built.string();
}

void printSummary(const DemoResult& r) {
  std::printf("\nScans (registration on the tunnel walls; truth = the emulator's real unit pose)\n");
  std::printf("%4s  %-24s %9s %9s %9s %9s %9s %12s %10s\n", "step", "unit", "points", "sail pts", "reg rms", "drift",
              "truth", "truth", "vs design");
  std::printf("%4s  %-24s %9s %9s %9s %9s %9s %12s %10s\n", "", "", "", "", "mm", "mm", "mm", "deg", "rms mm");
  for (const DemoUnitStep& s : r.scans)
    std::printf("%4d  %-24s %9zu %9zu %9.1f %9.1f %9.1f %12.3f %10.1f%s\n", s.step, s.unit.c_str(), s.points,
                s.sail_points, s.registration_rms_mm, s.drift_mm, s.truth_error_mm, s.truth_error_deg,
                s.deviation_rms_mm, s.partial ? "  PARTIAL" : s.analysed ? "" : "  NOT ANALYSED");
  std::printf("\nSections per step: flying (flying - design)\n");
  std::printf("%-14s %4s %7s %18s %18s %18s\n", "sail", "step", "height", "camber %", "draft %", "twist deg");
  for (const DemoSectionRow& s : r.sections)
    std::printf("%-14s %4d %6.0f%% %8.1f (%+6.1f) %8.1f (%+6.1f) %8.1f (%+6.1f)\n", s.sail.c_str(), s.step,
                100 * s.fraction, s.camber_pct, s.d_camber_pct, s.draft_pct, s.d_draft_pct, s.twist_deg, s.d_twist_deg);
  if (!r.warnings.empty()) {
    std::printf("\nWarnings (each once, with how often and at which trim steps it came):\n");
    for (const std::string& w : summariseWarnings(r.warnings)) std::printf("  %s\n", w.c_str());
  }
  std::printf("\nDatabase:   %s\n", r.database.c_str());
  for (const std::string& p : r.reports) std::printf("Report:     %s\n", p.c_str());
  for (const std::string& u : r.unit_files) std::printf("Unit file:  %s\n", u.c_str());
  std::printf("Forces in the database are simulated by the emulator, not measured.\n");
  std::printf("Finished in %.0f s. Open the results with:  %s %s\n", r.seconds, viewerPath().c_str(),
              r.database.c_str());
}

}  // namespace

void addDemoCommand(CLI::App& app) {
  auto o = std::make_shared<DemoCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "Run the whole product on emulated scanners in a wind tunnel (the main job)\n\n"
      "Run the whole product on emulated hardware: two scanner units in a wind tunnel (LMS511 on the mainsail, "
      "LMS111 on an A2 gennaker) sweep a test of trim steps through the real protocols (CoLa over TCP, the "
      "turntable over a pseudo-terminal); each cloud is registered into the boat frame on the tunnel walls, "
      "analysed, compared with its design and stored in DIR/sailshape.db, with the raw captures in DIR/captures "
      "and a PDF trim report per sail in DIR.");
  cmd->add_option("--dir", o->demo.dir, "Output folder (created; must not already hold a sailshape.db)")
      ->capture_default_str();
  cmd->add_option("--steps", o->demo.steps, "Trim steps; the gennaker tack is eased 20 mm (model scale) each step")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
  cmd->add_option("--sections", o->demo.sections, "Sections per sail, at k/(N+1) of luff and leech")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  cmd->add_option("--scan-lines", o->demo.scan_lines,
                  "Scan lines per sweep and unit (sets the turntable speed over its 100° sweep at 25 Hz)")
      ->check(CLI::Range(20, 2000))
      ->capture_default_str();
  cmd->add_flag("--coarse", o->demo.coarse,
               "Scanners at 0.5° steps instead of their finest at 25 Hz (LMS511 0.1667°, LMS111 0.25°)");
  cmd->add_option("--seed", o->demo.seed, "Seed of the emulated sensor noise")->capture_default_str();
  cmd->add_flag("--quiet", o->quiet, "No progress output (the summary is still printed)");
  cmd->callback([o] {
    ProgressBar bar(!o->quiet);
    auto log = [&](const std::string& m) {
      if (o->quiet) return;
      bar.finish();
      std::fprintf(stderr, "%s\n", m.c_str());
    };
    const DemoResult r = runDemo(o->demo, log, bar.progress());
    bar.finish();
    printSummary(r);
  });
}

}  // namespace sailshape::cli
