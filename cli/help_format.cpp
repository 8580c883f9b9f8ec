#include "cli/help_format.hpp"

#include <memory>
#include <sstream>

namespace sailshape::cli {
namespace {

constexpr size_t kOptionColumn = 30;  // where option descriptions start (CLI11's default column)

}  // namespace

std::string wrapText(const std::string& text, size_t width) {
  std::string out;
  std::istringstream lines(text);
  bool first_line = true;
  for (std::string line; std::getline(lines, line); first_line = false) {
    if (!first_line) out += '\n';
    // An indented line (an example, a list item) continues at its own indent.
    const size_t text_start = line.find_first_not_of(' ');
    const std::string indent = text_start == std::string::npos ? "" : line.substr(0, text_start);
    out += indent;
    size_t column = indent.size();
    bool line_empty = true;
    std::istringstream words(line);
    for (std::string word; words >> word; line_empty = false) {
      if (!line_empty && column + 1 + word.size() > width) {
        out += '\n' + indent;
        column = indent.size();
      } else if (!line_empty) {
        out += ' ';
        ++column;
      }
      out += word;
      column += word.size();
    }
  }
  return out;
}

HelpFormatter::HelpFormatter() { column_width(kOptionColumn); }

std::string HelpFormatter::make_subcommand(const CLI::App* sub) const {
  const std::string& desc = sub->get_description();
  std::stringstream out;
  CLI::detail::format_help(out, sub->get_display_name(true), desc.substr(0, desc.find('\n')), column_width_);
  return out.str();
}

std::string HelpFormatter::make_description(const CLI::App* app) const {
  const std::string desc = CLI::Formatter::make_description(app);
  return desc.empty() ? desc : wrapText(desc, kHelpWidth) + "\n\n";
}

std::string HelpFormatter::make_option_desc(const CLI::Option* opt) const {
  return wrapText(CLI::Formatter::make_option_desc(opt), kHelpWidth - kOptionColumn);
}

std::string HelpFormatter::make_footer(const CLI::App* app) const {
  // An example command line breaks before an option, with a shell continuation, so
  // it pastes as it is; other footer lines wrap as text.
  std::string out;
  std::istringstream lines(app->get_footer());
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  sailshape", 0) != 0) {
      out += wrapText(line, kHelpWidth) + "\n";
      continue;
    }
    size_t column = 0;
    for (size_t start = 0; start < line.size();) {
      size_t end = line.find(" --", start + 1);
      if (end == std::string::npos) end = line.size();
      const std::string chunk = line.substr(start, end - start);  // " --option value", or the command itself
      if (column > 0 && column + chunk.size() + 2 > kHelpWidth) {
        out += " \\\n   ";
        column = 3;
      }
      out += chunk;
      column += chunk.size();
      start = end;
    }
    out += "\n";
  }
  return out;
}

void useHelpFormatter(CLI::App& app) { app.formatter(std::make_shared<HelpFormatter>()); }

}  // namespace sailshape::cli
