#pragma once
// A trim step read back: where it belongs (campaign, session, boat, sail), its
// conditions and control settings, and the trim steps that make up a test.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/mesh.hpp"
#include "database/sqlite.hpp"

namespace sailshape {

// The campaign, session, boat and sail of a trim step. Text stored as NULL is empty.
struct TrimStepContext {
  std::string campaign, campaign_kind, place, campaign_start, session, session_started;
  std::string boat, boat_class;  // empty: the sail has no boat
  std::string sail, sail_type, size_variant, designer, version;
  std::string test;
  std::optional<Mesh> design_mesh;  // the sail's stored design, when there is one
};

// Empty when there is no trim step `trim_step_id`; DatabaseError for a damaged design mesh blob.
std::optional<TrimStepContext> trimStepContext(Database& db, int64_t trim_step_id);

// What was set and measured at a trim step; a value stored as NULL is absent.
struct TrimStepConditions {
  int step_order = 0;
  std::optional<double> awa_deg, aws_m_s;                  // apparent wind angle and speed
  std::optional<double> drive_n, side_n, heel_moment_nm;   // measured forces
  std::map<std::string, double> controls;                  // control-line settings by name
};

// Empty when there is no trim step `trim_step_id`.
std::optional<TrimStepConditions> trimStepConditions(Database& db, int64_t trim_step_id);

// One trim step of a test, with the newest of its scans that has an analysis.
struct TestStep {
  int64_t trim_step_id = 0;
  int64_t session_id = 0;
  std::string sail;
  int64_t analysed_scan_id = 0;  // 0: none of its scans has an analysis
};

// The trim steps of test `test` (by name) in step order, of every sail using
// that name, or only of sail `sail` when it is not empty. Empty for an unknown test.
std::vector<TestStep> testSteps(Database& db, const std::string& test, const std::string& sail = "");

}  // namespace sailshape
