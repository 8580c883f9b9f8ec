#include "viewer/catalog_tree.hpp"

#include <cmath>
#include <cstdio>

#include "database/queries.hpp"

namespace sailshape::viewer {
namespace {

size_t column(const Table& t, const std::string& name) {
  for (size_t i = 0; i < t.columns.size(); ++i)
    if (t.columns[i] == name) return i;
  throw DatabaseError("[loadCatalogTree] findScans has no column \"" + name + "\"");
}

std::string text(const Value& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  if (const auto* i = std::get_if<int64_t>(&v)) return std::to_string(*i);
  if (const auto* d = std::get_if<double>(&v)) return std::to_string(*d);
  return {};
}

std::optional<double> number(const Value& v) {
  if (const auto* d = std::get_if<double>(&v)) return *d;
  if (const auto* i = std::get_if<int64_t>(&v)) return static_cast<double>(*i);
  return std::nullopt;
}

}  // namespace

std::string TrimStepEntry::label() const {
  char buf[160];
  if (awa_deg)
    std::snprintf(buf, sizeof buf, "step %d · %s · AWA %.0f°", step, sail.c_str(), *awa_deg);
  else
    std::snprintf(buf, sizeof buf, "step %d · %s", step, sail.c_str());
  return buf;
}

std::string TestEntry::label() const { return name.empty() ? "(no test name)" : name; }

std::vector<int64_t> CatalogTree::scanIds() const {
  std::vector<int64_t> ids;
  for (const auto& c : campaigns)
    for (const auto& t : c.tests)
      for (const auto& s : t.steps)
        for (const auto& scan : s.scans) ids.push_back(scan.scan_id);
  return ids;
}

const TrimStepEntry* CatalogTree::stepOf(int64_t scan_id) const {
  for (const auto& c : campaigns)
    for (const auto& t : c.tests)
      for (const auto& s : t.steps)
        for (const auto& scan : s.scans)
          if (scan.scan_id == scan_id) return &s;
  return nullptr;
}

CatalogTree loadCatalogTree(Database& db) {
  const Table t = findScans(db);
  const size_t c_id = column(t, "scan_id"), c_campaign = column(t, "campaign"), c_test = column(t, "test"),
               c_step = column(t, "step"), c_sail = column(t, "sail"), c_awa = column(t, "awa_deg"),
               c_aws = column(t, "aws_m_s"), c_drive = column(t, "drive_n"), c_side = column(t, "side_n"),
               c_points = column(t, "point_count"), c_at = column(t, "scanned_at"), c_controls = column(t, "controls");
  CatalogTree tree;
  for (const auto& row : t.rows) {
    const std::string campaign = text(row[c_campaign]), test = text(row[c_test]), sail = text(row[c_sail]);
    const int step = static_cast<int>(number(row[c_step]).value_or(0));
    // Rows arrive ordered by campaign, test, step: a new group starts when a key changes.
    if (tree.campaigns.empty() || tree.campaigns.back().name != campaign) tree.campaigns.push_back({campaign, {}});
    auto& tests = tree.campaigns.back().tests;
    if (tests.empty() || tests.back().name != test) tests.push_back({test, {}});
    auto& steps = tests.back().steps;
    // Two sails tested at the same step order are two trim steps.
    TrimStepEntry* entry = nullptr;
    for (auto it = steps.rbegin(); it != steps.rend() && it->step == step; ++it)
      if (it->sail == sail) entry = &*it;
    if (!entry) {
      TrimStepEntry s;
      s.step = step;
      s.sail = sail;
      s.awa_deg = number(row[c_awa]);
      s.aws_m_s = number(row[c_aws]);
      s.drive_n = number(row[c_drive]);
      s.side_n = number(row[c_side]);
      s.controls = text(row[c_controls]);
      steps.push_back(std::move(s));
      entry = &steps.back();
    }
    ScanEntry scan;
    scan.scan_id = std::get<int64_t>(row[c_id]);
    scan.scanned_at = text(row[c_at]);
    scan.point_count = static_cast<int64_t>(number(row[c_points]).value_or(0));
    entry->scans.push_back(std::move(scan));
    ++tree.scan_count;
  }
  return tree;
}

}  // namespace sailshape::viewer
