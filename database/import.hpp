#pragma once
// Storing one scan — its trim step, the cloud and the `sailshape analyze` JSON —
// in one transaction: either all of it is in the file or none of it.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

// The full json header, not json_fwd.hpp: ImportMetadata holds its settings as
// a json value, which needs the complete type.
#include <nlohmann/json.hpp>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/design/design_compare.hpp"
#include "database/scan_record.hpp"
#include "database/sqlite.hpp"

namespace sailshape {

// Where a scan belongs. Campaign, session, boat, sail, scanner unit and trim
// step are found by name (and order) or created.
struct ImportMetadata {
  std::string campaign = "default";
  std::string campaign_kind = "full_scale";  // or "wind_tunnel"
  std::string session = "default";
  std::string boat;                          // empty: the sail has no boat
  std::string sail = "default";
  std::string sail_type;                     // set on a new sail, updates an existing one when given
  std::string test;                          // a series of trim steps
  int trim_step = 0;                         // order within the test
  std::optional<double> awa_deg, aws_m_s;    // apparent wind angle and speed
  std::optional<double> drive_n, side_n, heel_moment_nm;
  std::map<std::string, double> controls;    // control-line settings: tack_height, sheet, ...
  std::map<std::string, double> pressures_pa;  // per tap
  std::string scanner_unit;                  // serial; empty: unknown
  std::string scanned_at;                    // ISO 8601
  nlohmann::json settings;                   // acquisition settings
  std::string raw_capture;                   // reference to the raw capture
  std::string software_version = "0.1.0";
  // The region the sail flies in (database/scan_record.hpp ScanRegion); every
  // re-analysis of the stored cloud crops to it.
  std::optional<ScanRegion> region;
  // The analysis against the sail's current design, stored with it (design_comparisons).
  struct Comparison {
    DistanceStats stats;
    nlohmann::json details;  // e.g. {"sections": analysis_json sectionDeltasToJson}
  };
  std::optional<Comparison> design_comparison;
};

struct ImportResult {
  int64_t scan_id = 0;
  int64_t analysis_id = 0;   // 0 without an analysis
  int64_t trim_step_id = 0;
  size_t sections = 0;
};

// Called between the writes of an import ("scan", "analysis", "sections");
// tests use it to kill a writer mid-transaction.
using ImportHook = std::function<void(const std::string& stage)>;

// Stores a scan with an optional analysis document (the JSON of `sailshape
// analyze --json`), an optional cloud and, with the analysis, the surface it
// reconstructed (analyses.surface_mesh; reports draw it), in one transaction. Throws
// InvalidInput for a document without "sections" or bad metadata, DatabaseError
// (DatabaseBusy when locked) for SQLite failures; nothing is stored then.
ImportResult importScan(Database& db, const ImportMetadata& meta, const nlohmann::json* analysis,
                        const Cloud* cloud = nullptr, const ImportHook& hook = {}, const Mesh* surface = nullptr);

// Stores `analysis` (the JSON of `sailshape analyze --json`) as a new analysis of
// an existing scan, with the surface it reconstructed when given, in one
// transaction; the scan's earlier analyses stay. Returns
// the analysis id. Throws InvalidInput for a missing scan or a document without
// a "sections" array or with a fraction outside (0, 1).
int64_t addAnalysis(Database& db, int64_t scan_id, const nlohmann::json& analysis,
                    const std::string& software_version = "0.1.0", const Mesh* surface = nullptr);

// N×3 float64 little-endian, the layout of sections.curve.
std::vector<uint8_t> packCurve(const std::vector<Vec3>& curve);
std::vector<Vec3> unpackCurve(const std::vector<uint8_t>& blob);

}  // namespace sailshape
