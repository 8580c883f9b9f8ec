#pragma once
// What a trim report shows, read from the database: the sail and where it
// flew, and per trim step its conditions, forces, controls and sections.
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/sections/luff_curve.hpp"
#include "analysis/sections/sections.hpp"
#include "database/sqlite.hpp"
#include "database/trim_step.hpp"

namespace sailshape {

// One stored section. A value the analysis could not measure (NULL in the
// file) is NaN here, in `value` and in `uncertainty` (1σ, same units).
struct ReportSection {
  double fraction = 0;
  SectionParameters value, uncertainty;
  bool converged = true;
  std::vector<Vec3> curve;  // metres, boat frame, luff to leech
};

// A sail's outline measures with their 1σ: NaN where not stored (an analysis
// imported without its `sail` object, or a `sail` object without σ), or not
// measured (`top_length_m` of a sail without a peak).
struct OutlineMeasure {
  double value = std::numeric_limits<double>::quiet_NaN(), sigma = std::numeric_limits<double>::quiet_NaN();
};
struct ReportOutline {
  OutlineMeasure luff_length_m, leech_length_m, foot_length_m, top_length_m, area_m2;
  // The luff curve (SPEC §5): its largest sag in the sail's plane (LUFA) and to
  // leeward of it (LUSW), as % of the tack-head distance, and where along it.
  OutlineMeasure lufa_sag_pct, lufa_position_pct, lusw_sag_pct, lusw_position_pct;
  double beam_footprint_m = 0;  // how far the edges were moved out for the scanner's beam (0: not)
};

// The same measures from an outline and its luff curve as analysed (the design's).
ReportOutline reportOutline(const SailOutline& outline, const LuffCurve& luff);

struct ReportStep {
  int64_t scan_id = 0, trim_step_id = 0, analysis_id = 0;
  int step_order = 0;
  std::string scanned_at;  // ISO 8601, empty when unknown
  std::optional<double> awa_deg, aws_m_s, drive_n, side_n, heel_moment_nm;
  std::map<std::string, double> controls;  // control-line settings as stored
  std::vector<ReportSection> sections;     // the latest analysis, by fraction
  std::vector<UnmeasuredSection> unmeasured;  // sections it was asked for but could not measure, with why
  ReportOutline outline;                   // the latest analysis's (analyses.sail)
  std::optional<Mesh> surface;             // the surface it reconstructed; none when not stored
  Cloud cloud;                             // the stored cloud; empty when none was stored
};

// Where the report's trim steps belong (campaign, session, boat, sail, test: empty
// for a single scan without one; the sail's stored design, when there is one) and
// the steps themselves.
struct ReportData : TrimStepContext {
  std::vector<ReportStep> steps;  // one per trim step, in step order
};

// The scan `scan_id` with its trim step, sail and latest analysis. Throws
// InvalidInput for an unknown scan or a scan without an analysis.
ReportData loadScanReport(Database& db, int64_t scan_id);

// Every trim step of test `test` (by name), each with its latest analysed
// scan. `sail` picks the sail when the test name is used for more than one;
// empty: the test must belong to one sail. Throws InvalidInput for an unknown
// test, an ambiguous one, or a test without analysed scans.
ReportData loadTestReport(Database& db, const std::string& test, const std::string& sail = "");

}  // namespace sailshape
