#pragma once
// The SQL that differs between the store's backends, in one place. Queries and
// migrations are written in SQLite's spelling; these turn them into PostgreSQL's.
#include <string>

namespace sailshape::detail {

// `?` placeholders (outside quotes) numbered $1, $2, ... as PostgreSQL wants
// them; `count` receives how many there were.
std::string numberPlaceholders(const std::string& sql, int* count);

// A migration's DDL for PostgreSQL: INTEGER PRIMARY KEY becomes a BIGINT
// identity (BY DEFAULT, so a copy keeps its ids), INTEGER BIGINT, REAL DOUBLE
// PRECISION (PostgreSQL's REAL is 4 bytes), BLOB BYTEA, TEXT compares bytewise
// as SQLite's does (COLLATE "C", so ORDER BY answers alike), WITHOUT ROWID and
// SQLite's strftime('now') default go.
std::string postgresDdl(const std::string& sqlite_ddl);

// A REAL as SQLite writes it as text ("%!.15g": 0.2, 1.0, 1.0e+15), so text
// built from numbers reads the same from either backend.
std::string sqliteRealText(double value);

// `location` shown in messages: a URL's password replaced by "***".
std::string redactedLocation(const std::string& location);

}  // namespace sailshape::detail

namespace sailshape::detail {

// After rows were inserted with their ids: the SQL that moves `table`'s id
// sequence past them (PostgreSQL); empty where none is needed (SQLite).
std::string identityResync(bool postgres, const std::string& table);

}  // namespace sailshape::detail
