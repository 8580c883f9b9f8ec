#pragma once
// What surrounds the scans: sails with their design, scanner units with their
// calibration history, registrations and design-vs-flying statistics.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "analysis/core/mesh.hpp"
#include "analysis/design/design_compare.hpp"
#include "database/sqlite.hpp"

namespace sailshape {

struct SailInfo {
  std::string name;
  std::string type, size_variant, designer, version;  // empty: left as stored
  std::string boat;                                   // empty: left as stored; created when new
};

// Creates or updates the sail `info.name`; a design mesh that differs from the
// sail's current one is stored as its next design version (addDesignVersion), with
// the parameters when given. Returns the sail's id. One transaction.
int64_t upsertSail(Database& db, const SailInfo& info, const Mesh* design_mesh = nullptr,
                   const nlohmann::json* design_params = nullptr);

// The sail's current design mesh (its highest design version); throws InvalidInput when the sail or its design is missing.
Mesh sailDesignMesh(Database& db, const std::string& sail);

// Where a design version came from: the file and what the importer applied
// (analysis/io/design_import.hpp); empty when unknown.
struct DesignSource {
  std::string file, format, unit, axes;
};

struct DesignVersion {
  int version = 0;             // 1, 2, ... per sail; the highest is current
  std::string added_at;        // ISO 8601, UTC
  DesignSource source;
  size_t vertices = 0, triangles = 0;
  bool current = false;
};

// Stores `mesh` (metres, boat frame) as the sail's next design version and makes it
// current, in one transaction; the sail is created when new. Returns the version.
// Throws InvalidInput for an empty mesh or a non-finite vertex.
int addDesignVersion(Database& db, const std::string& sail, const Mesh& mesh, const DesignSource& source,
                     const nlohmann::json* params = nullptr);
// The sail's design versions, oldest first; throws InvalidInput when there is no such sail.
std::vector<DesignVersion> designVersions(Database& db, const std::string& sail);
// Version `version` of the sail's design (0: the current one); throws InvalidInput
// when the sail or the version is missing.
Mesh designVersionMesh(Database& db, const std::string& sail, int version = 0);
// The sail's current design version number; 0 when it has none (or no such sail).
int currentDesignVersion(Database& db, const std::string& sail);

// Mesh blob: "SSM1", uint64 vertex count, uint64 triangle count, float64 xyz (metres), uint32 indices.
std::vector<uint8_t> packMesh(const Mesh& mesh);
Mesh unpackMesh(const std::vector<uint8_t>& blob);

struct Calibration {
  std::string calibrated_at;  // ISO 8601
  double p_m = 0;             // SPEC §2 mirror-to-axis offset
  double theta_deg = 0;       // SPEC §2 scan plane tilt
};

// Adds a calibration of scanner `serial` (the unit is created when new).
int64_t addCalibration(Database& db, const std::string& serial, const Calibration& calibration);
// The unit's calibration in force at `at` (the latest not after it), if any.
std::optional<Calibration> calibrationAt(Database& db, const std::string& serial, const std::string& at);

// Scanner-to-boat transform of a scan (row-major JSON in the file).
int64_t addRegistration(Database& db, int64_t scan_id, const Eigen::Matrix4d& transform, double fitness, double rmse_m);
Eigen::Matrix4d scanTransform(Database& db, int64_t scan_id);  // the latest; throws InvalidInput when none

// Design-vs-flying statistics of an analysis against its sail's design.
// `details` (a JSON object, e.g. per-section figures) is stored with the
// statistics in design_comparisons.stats; without it, the statistics alone.
int64_t addDesignComparison(Database& db, int64_t analysis_id, const std::string& sail, const DistanceStats& stats,
                            const nlohmann::json& details);
int64_t addDesignComparison(Database& db, int64_t analysis_id, const std::string& sail, const DistanceStats& stats);

}  // namespace sailshape
