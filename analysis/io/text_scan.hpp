#pragma once
// Shared by the file readers and writers (cloud_io.cpp, mesh_io.cpp): error
// messages that name the file and line or byte, whole-file I/O, line and token
// scanning, number parsing and formatting. Internal to analysis/.
#include <charconv>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "analysis/core/errors.hpp"

namespace sailshape::detail {

// ---------------------------------------------------------------------------
// Errors: "<path>: line 7: <problem>", "<path>: byte 1234: <problem>", "<path>: <problem>".

FileError fileError(const std::string& path, const std::string& problem);
FileError atLine(const std::string& path, size_t line, const std::string& problem);
FileError atByte(const std::string& path, size_t byte, const std::string& problem);

// A token as shown in a message: quoted, cut short if it is long (binary junk in a text file).
std::string quoted(std::string_view token);

std::string lowercase(std::string_view s);

// Lowercased, with the dot: ".ply".
std::string extensionOf(const std::string& path);

// ---------------------------------------------------------------------------
// Whole-file I/O; failures are FileErrors naming the path.

std::string readWholeFile(const std::string& path);
void writeWholeFile(const std::string& path, const std::string& content);

// ---------------------------------------------------------------------------
// Text scanning.

inline bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && isBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && isBlank(s.back())) s.remove_suffix(1);
  return s;
}

// Lines of a text region, '\n' or "\r\n" terminated, numbered from `first_line`.
class LineReader {
 public:
  LineReader(const char* begin, const char* end, size_t first_line = 1) : p_(begin), end_(end), line_(first_line - 1) {}

  bool next(std::string_view& line) {
    if (p_ == end_) return false;
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', static_cast<size_t>(end_ - p_)));
    const char* stop = nl ? nl : end_;
    line = std::string_view(p_, static_cast<size_t>(stop - p_));
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    p_ = nl ? nl + 1 : end_;
    ++line_;
    return true;
  }

  // Skips lines that hold only blanks.
  bool nextNonEmpty(std::string_view& line) {
    while (next(line))
      if (!trim(line).empty()) return true;
    return false;
  }

  size_t line() const { return line_; }  // number of the line last returned
  const char* position() const { return p_; }

 private:
  const char* p_;
  const char* end_;
  size_t line_;
};

void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens);

// Fields separated by ',' or ';' (blanks around them trimmed) or by runs of blanks.
// "1,,3" yields an empty middle field; a trailing separator is ignored.
void splitFields(std::string_view line, std::vector<std::string_view>& tokens);

// ---------------------------------------------------------------------------
// Numbers.

enum class Parsed { Ok, NotANumber, OutOfRange };

// Whole-token parse: "1.5abc" is not a number; "nan" and "inf" are (the callers decide).
Parsed parseNumber(std::string_view token, double& value);

// parseNumber, or a FileError at `line` ("empty value", "non-numeric value '...'", "value out of range '...'").
double numberOnLine(const std::string& path, size_t line, std::string_view token);

template <typename Int>
bool parseInteger(std::string_view token, Int& value) {
  const char* b = token.data();
  const char* e = b + token.size();
  if (b != e && *b == '+') ++b;
  if (b == e) return false;
  const auto r = std::from_chars(b, e, value);
  return r.ec == std::errc() && r.ptr == e;
}

// Shortest text that reads back to the same value.
template <typename T>
void appendNumber(std::string& out, T v) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof(b), v);
  out.append(b, r.ptr);
}

}  // namespace sailshape::detail
