#pragma once
// The database browser's model: campaign → test → trim step → scan, built
// from findScans so the viewer holds no SQL of its own.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "database/sqlite.hpp"

namespace sailshape::viewer {

struct ScanEntry {
  int64_t scan_id = 0;
  std::string scanned_at;   // ISO 8601, may be empty
  int64_t point_count = 0;
};

struct TrimStepEntry {
  int step = 0;
  std::string sail;
  std::optional<double> awa_deg, aws_m_s, drive_n, side_n;
  std::string controls;     // "name=value;..." as stored
  std::vector<ScanEntry> scans;
  std::string label() const;  // "step 2 · main · AWA 32°"
};

struct TestEntry {
  std::string name;         // empty: scans imported without a test name
  std::vector<TrimStepEntry> steps;
  std::string label() const;
};

struct CampaignEntry {
  std::string name;
  std::vector<TestEntry> tests;
};

struct CatalogTree {
  std::vector<CampaignEntry> campaigns;
  size_t scan_count = 0;
  // The scan ids in browsing order (for next/previous).
  std::vector<int64_t> scanIds() const;
  // Where `scan_id` sits, or nullptr.
  const TrimStepEntry* stepOf(int64_t scan_id) const;
};

// Reads every scan of `db` into the tree (ordered by campaign, test, step, scan).
CatalogTree loadCatalogTree(Database& db);

}  // namespace sailshape::viewer
