#pragma once
// How `sailshape` lays out its help. A command's description is a one-line
// summary, then a blank line and the details; the command list shows the summary
// alone and the command's own --help the whole text. Descriptions are wrapped to
// kHelpWidth columns, and each command's footer carries its examples.
#include <CLI/CLI.hpp>
#include <string>

namespace sailshape::cli {

inline constexpr size_t kHelpWidth = 110;  // columns of a wrapped help line

// `text` with its lines broken at spaces so none runs past `width` columns
// (words longer than that stay whole); existing line breaks are kept.
std::string wrapText(const std::string& text, size_t width);

class HelpFormatter : public CLI::Formatter {
 public:
  HelpFormatter();
  std::string make_subcommand(const CLI::App* sub) const override;
  std::string make_description(const CLI::App* app) const override;
  std::string make_option_desc(const CLI::Option* opt) const override;
  std::string make_footer(const CLI::App* app) const override;
};

// Gives `app` (and every subcommand added to it afterwards) the HelpFormatter.
void useHelpFormatter(CLI::App& app);

// Gives every command of `app` (added before) its "Examples:" footer
// (cli/help_examples.cpp).
void addExamples(CLI::App& app);

}  // namespace sailshape::cli
