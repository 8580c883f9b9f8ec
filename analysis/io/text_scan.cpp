#include "analysis/io/text_scan.hpp"

#include <cctype>
#include <cerrno>
#include <filesystem>
#include <fstream>

namespace sailshape::detail {

FileError fileError(const std::string& path, const std::string& problem) { return FileError(path + ": " + problem); }

FileError atLine(const std::string& path, size_t line, const std::string& problem) {
  return FileError(path + ": line " + std::to_string(line) + ": " + problem);
}

FileError atByte(const std::string& path, size_t byte, const std::string& problem) {
  return FileError(path + ": byte " + std::to_string(byte) + ": " + problem);
}

std::string quoted(std::string_view token) {
  constexpr size_t kMax = 40;
  if (token.size() > kMax) return "'" + std::string(token.substr(0, kMax)) + "...'";
  return "'" + std::string(token) + "'";
}

std::string lowercase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string extensionOf(const std::string& path) { return lowercase(std::filesystem::path(path).extension().string()); }

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw fileError(path, "cannot open file (is a directory)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fileError(path, std::string("cannot open file (") + std::strerror(errno) + ")");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw fileError(path, "cannot read file");
  in.seekg(0, std::ios::beg);
  std::string buf(static_cast<size_t>(size), '\0');
  if (size > 0 && !in.read(buf.data(), size)) throw fileError(path, "cannot read file");
  return buf;
}

void writeWholeFile(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw fileError(path, std::string("cannot open file for writing (") + std::strerror(errno) + ")");
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out) throw fileError(path, "write failed");
}

namespace {
// Tokens between blanks; with `separators`, a ',' or ';' (blanks around it
// allowed) also ends a token.
void splitTokens(std::string_view line, std::vector<std::string_view>& tokens, bool separators) {
  tokens.clear();
  const char* p = line.data();
  const char* end = p + line.size();
  auto separator = [&](char c) { return separators && (c == ',' || c == ';'); };
  while (true) {
    while (p < end && isBlank(*p)) ++p;
    if (p == end) return;
    const char* start = p;
    while (p < end && !isBlank(*p) && !separator(*p)) ++p;
    tokens.emplace_back(start, static_cast<size_t>(p - start));
    while (p < end && isBlank(*p)) ++p;
    if (p < end && separator(*p)) ++p;
  }
}
}  // namespace

void splitWhitespace(std::string_view line, std::vector<std::string_view>& tokens) { splitTokens(line, tokens, false); }

void splitFields(std::string_view line, std::vector<std::string_view>& tokens) { splitTokens(line, tokens, true); }

Parsed parseNumber(std::string_view token, double& value) {
  const char* b = token.data();
  const char* e = b + token.size();
  if (b != e && *b == '+') ++b;  // from_chars rejects a leading '+'
  if (b == e) return Parsed::NotANumber;
  const auto r = std::from_chars(b, e, value);
  if (r.ec == std::errc::result_out_of_range && r.ptr == e) return Parsed::OutOfRange;
  if (r.ec != std::errc() || r.ptr != e) return Parsed::NotANumber;
  return Parsed::Ok;
}

double numberOnLine(const std::string& path, size_t line, std::string_view token) {
  double value = 0;
  switch (parseNumber(token, value)) {
    case Parsed::Ok:
      return value;
    case Parsed::OutOfRange:
      throw atLine(path, line, "value out of range " + quoted(token));
    case Parsed::NotANumber:
      break;
  }
  if (token.empty()) throw atLine(path, line, "empty value");
  throw atLine(path, line, "non-numeric value " + quoted(token));
}

}  // namespace sailshape::detail
