#include <cctype>

#include "cli/commands.hpp"

namespace sailshape::cli {
namespace {

bool g_verbose = false;

}  // namespace

void addVerboseFlag(CLI::App& app) {
  app.add_flag("--verbose", g_verbose,
               "Longer diagnostics: errors name the function that raised them, db check lists the problems it found");
  // Subcommands created after this inherit it: `sailshape db check F --verbose`
  // hands the flag up to the app, as does `sailshape --verbose db check F`.
  app.fallthrough();
}

bool verbose() { return g_verbose; }

std::string userMessage(const std::string& what) {
  if (g_verbose || what.empty() || what[0] != '[') return what;
  const size_t close = what.find("] ");
  if (close == std::string::npos || close < 2) return what;
  for (size_t i = 1; i < close; ++i) {
    const unsigned char c = static_cast<unsigned char>(what[i]);
    if (!std::isalnum(c) && c != '_' && c != ':') return what;  // not a function name
  }
  return what.substr(close + 2);
}

}  // namespace sailshape::cli
