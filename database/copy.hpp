#pragma once
// Copying one store into another (SQLite file or PostgreSQL server, either
// way): every row of every sailshape table, in one transaction on the
// destination.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "database/store.hpp"

namespace sailshape {

struct CopyOptions {
  // false: the destination must hold no rows, and every row keeps its id.
  // true: rows are added with new ids; campaigns, boats, sails, scanner units,
  // sessions and trim steps the destination already has (by name; a trim step
  // by session, sail, test and order) are used, not duplicated, and keep their
  // values there; scans, analyses, calibrations and the rest are added.
  bool append = false;
};

struct CopyResult {
  std::vector<std::pair<std::string, size_t>> rows_added;  // per table, in copy order
  size_t total_rows = 0;
};

// Both stores must be at kSchemaVersion (openSailDatabase). The source is read
// from one snapshot; the destination gets all of it or, on any error, nothing.
// Throws InvalidInput for a destination that holds rows (without append) or is
// the source itself, DatabaseError for the stores' failures.
CopyResult copyStore(Database& source, Database& dest, const CopyOptions& options = {});

}  // namespace sailshape
