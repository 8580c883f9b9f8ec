#pragma once
// Subcommands of the `sailshape` command. Each registers its options on the
// app and runs through a callback; errors propagate as exceptions to main().
#include <CLI/CLI.hpp>

namespace sailshape::cli {

void addAnalyzeCommand(CLI::App& app);
void addSimulateCommand(CLI::App& app);
void addDesignCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addDbCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addReplayCommand(CLI::App& app);
void addReportCommand(CLI::App& app);
void addRegisterCommand(CLI::App& app);
void addEmulateCommand(CLI::App& app);
void addScanCommand(CLI::App& app);
void addScannerCommand(CLI::App& app);

}  // namespace sailshape::cli
