#pragma once
// One stored scan read back for display and re-analysis: its place in the
// catalogue, the cloud and the sections of its latest analysis.
#include <cstdint>
#include <optional>
#include <string>

// The full json header, not json_fwd.hpp: ScanRecord holds json values (its
// parameters and settings), which need the complete type.
#include <nlohmann/json.hpp>
#include <Eigen/Geometry>

#include "analysis/core/cloud.hpp"
#include "analysis/core/mesh.hpp"
#include "analysis/sections/sections.hpp"
#include "database/sqlite.hpp"

namespace sailshape {

// The box a scan's sail flies in (boat frame, metres: its design's box grown by a
// margin), from the design version it was drawn around (0: none stored).
struct ScanRegion {
  Eigen::AlignedBox3d box;
  int design_version = 0;
};
// {"box_m": [xmin, xmax, ymin, ymax, zmin, zmax], "design_version": n}, as scans.region holds it.
nlohmann::json regionToJson(const ScanRegion& region);
// Empty for null or a document that is not a region.
std::optional<ScanRegion> regionFromJson(const nlohmann::json& j);

struct ScanRecord {
  int64_t scan_id = 0;
  int64_t trim_step_id = 0;
  int64_t analysis_id = 0;         // latest analysis; 0 when the scan has none
  std::string campaign, test, sail, scanned_at;
  int step = 0;
  std::optional<double> awa_deg;
  bool has_design = false;         // the sail has a stored design mesh
  std::optional<Cloud> cloud;      // absent when only the analysis was imported
  // The latest analysis's sections (and those it could not measure); luff/leech
  // points are the curve's ends and max_camber_point is not stored (left zero); a
  // parameter stored as NULL (not measurable) is NaN.
  SectionAnalysis sections;
  std::optional<Mesh> surface;     // the surface that analysis reconstructed, when stored with it (schema 4)
  nlohmann::json analysis_params;  // the pipeline parameters it ran with (null when unknown)
  nlohmann::json settings;         // the acquisition settings stored with the scan (null when none)
  std::optional<Eigen::Matrix4d> registration;  // the latest scanner-to-boat transform, when registered
  std::optional<ScanRegion> region;             // where the sail flies; empty: the whole cloud
};

// The id of scan `scan_id`'s latest analysis; 0 when it has none.
int64_t latestAnalysisId(Database& db, int64_t scan_id);

// Where a scan sits, without its cloud.
struct ScanSummary {
  int64_t trim_step_id = 0;  // 0: the scan belongs to no trim step
  int64_t analysis_id = 0;   // latest analysis; 0 when the scan has none
  std::string scanned_at;    // ISO 8601, empty when unknown
};
// Empty when there is no scan `scan_id`.
std::optional<ScanSummary> scanSummary(Database& db, int64_t scan_id);

// The stored cloud of scan `scan_id`; empty when none was stored (or no such
// scan). Throws DatabaseError for a damaged cloud blob.
std::optional<Cloud> scanCloud(Database& db, int64_t scan_id);

// The sections of analysis `analysis_id` by fraction, as ScanRecord::sections
// holds them (a parameter stored as NULL is NaN; luff and leech points are the
// curve's ends).
std::vector<Section> analysisSections(Database& db, int64_t analysis_id);

// The outline analysis `analysis_id` stored (analyses.sail: the `sail` object of
// `sailshape analyze --json`, its luff curve inside) as JSON text; empty when none.
std::string analysisOutlineJson(Database& db, int64_t analysis_id);

// The surface analysis `analysis_id` reconstructed (analyses.surface_mesh: metres,
// boat frame); none for an analysis stored without it (imported from its JSON
// alone, or before schema version 4). Throws DatabaseError for a damaged blob.
std::optional<Mesh> analysisSurface(Database& db, int64_t analysis_id);

// The sections analysis `analysis_id` was asked for but could not measure, with
// why (stored in its diagnostics by importScan); empty when there were none.
std::vector<UnmeasuredSection> unmeasuredSections(Database& db, int64_t analysis_id);

// Throws InvalidInput when there is no scan `scan_id`, DatabaseError for a damaged cloud blob.
ScanRecord loadScanRecord(Database& db, int64_t scan_id);

}  // namespace sailshape
