#pragma once
// The reference-database queries. Each returns a Table that table_export.hpp writes
// as CSV or JSON. A scan's sections are those of its latest analysis.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "database/sqlite.hpp"

namespace sailshape {

using Value = std::variant<std::monostate, int64_t, double, std::string>;  // monostate: NULL

struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<Value>> rows;
};

// Every field is optional; set ones are ANDed.
struct ScanFilter {
  std::optional<int64_t> scan_id;
  std::optional<std::string> boat, sail, sail_type, campaign, test;
  std::optional<double> awa_min_deg, awa_max_deg;
  std::optional<std::string> control;                // a control setting that must be present ...
  std::optional<double> control_min, control_max;    // ... within these bounds
};

// One row per scan: scan_id, campaign, boat, sail, sail_type, test, step, awa_deg,
// aws_m_s, drive_n, side_n, heel_moment_nm, point_count, scanned_at, controls
// ("name=value;..."), ordered by campaign, test, step, scan.
Table findScans(Database& db, const ScanFilter& filter = {});

// One row per section of the matching scans: scan_id, sail, test, step, awa_deg,
// fraction, every parameter and its u_ uncertainty, converged.
Table findSections(Database& db, const ScanFilter& filter = {});

// The section parameters sailshape stores; names as in the analysis JSON.
const std::vector<std::string>& sectionParameterNames();

// `parameter` (e.g. camber_pct) at the section nearest `fraction` over the trim
// steps of `test`, in step order: step, awa_deg, scan_id, fraction, value,
// uncertainty, controls. A step whose analysis left a nearer section unmeasured
// has NULL fraction, value and uncertainty. Throws InvalidInput for an unknown
// parameter.
Table parameterEvolution(Database& db, const std::string& test, const std::string& parameter, double fraction,
                         const ScanFilter& filter = {});

// Two sails side by side at the same apparent wind: for each sail, its scan
// with AWA nearest `awa_deg` (within ± tolerance), sections by fraction:
// fraction, then per sail <sail>:scan_id, <sail>:awa_deg and each parameter.
Table compareSails(Database& db, const std::string& sail_a, const std::string& sail_b, double awa_deg,
                   double tolerance_deg = 5.0);

enum class TrimCriterion { Drive, DriveOverSide };

// Trim steps with measured forces in [awa_min, awa_max], best first:
// trim_step_id, campaign, sail, test, step, awa_deg, drive_n, side_n, drive_side, controls.
Table bestTrimSteps(Database& db, double awa_min_deg, double awa_max_deg, TrimCriterion criterion, int limit = 1,
                    const ScanFilter& filter = {});

}  // namespace sailshape
