#pragma once
// Subcommands of the `sailshape` command. Each registers its options on the
// app and runs through a callback; errors propagate as exceptions to main().
#include <CLI/CLI.hpp>

#include <string>

namespace sailshape::cli {

void addAnalyzeCommand(CLI::App& app);
void addSimulateCommand(CLI::App& app);
void addDesignCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addFitCommand(CLI::App& app);
void addDbCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addReplayCommand(CLI::App& app);
void addReportCommand(CLI::App& app);
void addRegisterCommand(CLI::App& app);
void addEmulateCommand(CLI::App& app);
void addScanCommand(CLI::App& app);
void addScannerCommand(CLI::App& app);
void addCropCommand(CLI::App& app);

// --unit and --axes of a command that reads a design file (DesignImportOptions' two fields).
void addDesignFileOptions(CLI::App* cmd, std::string& unit, std::string& axes);

// The global --verbose flag; add it before the subcommands, which inherit it.
void addVerboseFlag(CLI::App& app);
bool verbose();
// An exception's message for the user: errors carry the function that raised
// them ("[Statement::step] f.db: ..."), which only --verbose shows.
std::string userMessage(const std::string& what);

}  // namespace sailshape::cli
