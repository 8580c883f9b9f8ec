#pragma once
// The main job end to end (issue 9), on emulated hardware: two scanner units in
// a wind tunnel (one on the mainsail, one on an A2 gennaker) scan a test of
// trim steps through the real protocols (CoLa over TCP, the turntable over a
// pty), every cloud is registered into the boat frame on the tunnel walls,
// analysed, compared with its design and stored in the database.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "analysis/core/progress.hpp"
#include "cli/warning_summary.hpp"

namespace sailshape::cli {

struct DemoOptions {
  // Receives sailshape.db, the unit files, emulator-truth.json, the reports, captures/ and clouds/.
  std::string dir = "demo-output";
  int steps = 3;                       // trim steps of the test (gennaker tack eased each step)
  int sections = 3;                    // per sail, SPEC §5 fractions k/(N+1)
  // Per sweep and unit: sets the turntable speed. 400 lines, 0.25° apart, give the upper
  // sections' short chords enough cut points near either end to read their entry and exit.
  int scan_lines = 400;
  // Scanner angular step: the finest each model offers at 25 Hz (LMS511 0.1667°, LMS111 0.25°), or 0.5° when coarse.
  bool coarse = false;
  uint64_t seed = 1;                   // emulator noise
};

struct DemoSectionRow {
  std::string sail;
  int step = 0;
  double fraction = 0;
  double camber_pct = 0, draft_pct = 0, twist_deg = 0;        // flying
  double d_camber_pct = 0, d_draft_pct = 0, d_twist_deg = 0;  // flying − design
};

struct DemoUnitStep {
  std::string unit, sail;
  int step = 0;
  size_t points = 0, sail_points = 0;
  bool partial = false;
  bool analysed = false;         // false: the analysis failed (DemoResult::warnings says why); the scan is stored
  double start_spread_ms = 0;   // between the two units' sweep starts
  double registration_rms_mm = 0;
  double drift_mm = 0;          // this step's wall registration against the stored transform
  double truth_error_mm = 0;    // registered pose against the emulator's true pose (self-check)
  double truth_error_deg = 0;
  double deviation_rms_mm = 0;  // flying to design
  int64_t scan_id = 0;
};

struct DemoResult {
  std::string database;
  std::vector<std::string> reports;  // one PDF trim report per sail
  std::vector<std::string> unit_files;
  std::vector<DemoUnitStep> scans;
  std::vector<DemoSectionRow> sections;
  std::vector<StepWarning> warnings;  // as raised, one per section, sail and step
  double seconds = 0;
};

// Stage messages for the CLI ("step 2/3: tunnel-main-lms511: analysing Demo 36 main", ...); progress within a stage goes to `progress`.
using DemoLog = std::function<void(const std::string& message)>;

// Throws InvalidInput for bad options (and when `dir` already holds a sailshape.db),
// and whatever a stage throws when it cannot do its job; a step that fails leaves
// every earlier step stored.
DemoResult runDemo(const DemoOptions& options, const DemoLog& log = {}, const Progress& progress = {});

}  // namespace sailshape::cli
