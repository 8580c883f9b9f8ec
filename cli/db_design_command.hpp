#pragma once
// `sailshape db design`: registered by `db` with its DB option and opener.
#include <functional>

#include <CLI/CLI.hpp>

#include "database/sqlite.hpp"

namespace sailshape::cli {

// `add_db` adds the DB positional and --busy-timeout to a subcommand; `open` opens
// that existing database for the named command (a missing one says to run db init).
void addDbDesignCommand(CLI::App* db, const std::function<void(CLI::App*)>& add_db,
                        const std::function<Database(const char*)>& open);

}  // namespace sailshape::cli
