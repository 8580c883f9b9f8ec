#pragma once
// The sailshape database schema and its migrations (PRAGMA user_version).
#include <string>

#include "database/sqlite.hpp"

namespace sailshape {

// The schema version this build writes; version 0 is an empty file.
constexpr int kSchemaVersion = 5;

// Brings the schema from its current user_version up to `target_version`, each
// step in its own transaction (a failed step leaves the previous version).
// Throws DatabaseError for a database newer than this build or a target
// outside [current, kSchemaVersion].
void migrateSchema(Database& db, int target_version = kSchemaVersion);

// Opens a sailshape database and migrates it to kSchemaVersion. A file that is
// not an SQLite database, or is newer than this build, throws and stays untouched.
Database openSailDatabase(const std::string& path, const OpenOptions& options = {});

}  // namespace sailshape
