// The `sailshape` command: parses arguments, calls the libraries, and turns any
// error into one line on stderr with a non-zero exit.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "analysis/core/errors.hpp"
#include "cli/commands.hpp"
#include "cli/help_format.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "sailshape: measure flying sail shapes from laser scans and compare them with their design.\n"
      "Units are SI (metres); angles in degrees on the command line. Boat frame: +X forward, +Y port, +Z up."};
  sailshape::cli::useHelpFormatter(app);  // before the commands: they take it from the app
  app.require_subcommand(1);
  app.set_version_flag("--version", "sailshape 0.1.0");
  sailshape::cli::addVerboseFlag(app);
  sailshape::cli::addAnalyzeCommand(app);
  sailshape::cli::addSimulateCommand(app);
  sailshape::cli::addDesignCommand(app);
  sailshape::cli::addCompareCommand(app);
  sailshape::cli::addFitCommand(app);
  sailshape::cli::addDemoCommand(app);
  sailshape::cli::addDbCommand(app);
  sailshape::cli::addReplayCommand(app);
  sailshape::cli::addReportCommand(app);
  sailshape::cli::addRegisterCommand(app);
  sailshape::cli::addEmulateCommand(app);
  sailshape::cli::addScanCommand(app);
  sailshape::cli::addScannerCommand(app);
  sailshape::cli::addCropCommand(app);
  sailshape::cli::addExamples(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "sailshape: %s (see --help)\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sailshape: error: %s\n", sailshape::cli::userMessage(e.what()).c_str());
    return 1;
  }
  return 0;
}
