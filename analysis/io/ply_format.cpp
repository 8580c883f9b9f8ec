#include "analysis/io/ply_format.hpp"

#include <cmath>

#include "analysis/io/text_scan.hpp"

namespace sailshape::detail {

namespace {

std::optional<Scalar> plyScalar(std::string_view name) {
  static const std::pair<const char*, Scalar> kNames[] = {
      {"char", Scalar::Int8},      {"int8", Scalar::Int8},       {"uchar", Scalar::UInt8},
      {"uint8", Scalar::UInt8},    {"short", Scalar::Int16},     {"int16", Scalar::Int16},
      {"ushort", Scalar::UInt16},  {"uint16", Scalar::UInt16},   {"int", Scalar::Int32},
      {"int32", Scalar::Int32},    {"uint", Scalar::UInt32},     {"uint32", Scalar::UInt32},
      {"float", Scalar::Float32},  {"float32", Scalar::Float32}, {"double", Scalar::Float64},
      {"float64", Scalar::Float64}};
  for (const auto& [n, t] : kNames)
    if (name == n) return t;
  return std::nullopt;
}

std::string elementNoun(const PlyElement& e) {
  if (e.name == "vertex") return "vertices";
  if (e.name == "face") return "faces";
  return "'" + e.name + "' elements";
}

}  // namespace

bool isIntegerScalar(Scalar t) { return t != Scalar::Float32 && t != Scalar::Float64; }

std::optional<Vec3> viewpointComment(const std::vector<std::string_view>& tokens, size_t first) {
  if (tokens.size() != first + 4 || tokens[first] != "viewpoint") return std::nullopt;
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    double x = 0;
    if (parseNumber(tokens[first + 1 + k], x) != Parsed::Ok || !std::isfinite(x)) return std::nullopt;
    v[k] = x;
  }
  return v;
}

std::optional<std::vector<double>> lostBetaComment(const std::vector<std::string_view>& tokens, size_t first) {
  if (tokens.size() < first + 2 || tokens[first] != "lost_beta_rad") return std::nullopt;
  std::vector<double> out;
  for (size_t k = first + 1; k < tokens.size(); ++k) {
    double x = 0;
    if (parseNumber(tokens[k], x) != Parsed::Ok || !std::isfinite(x)) return std::nullopt;
    out.push_back(x);
  }
  return out;
}

PlyHeader parsePlyHeader(const std::string& path, const std::string& buf) {
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::string_view line;
  if (!lines.next(line) || trim(line) != "ply") throw atLine(path, 1, "not a PLY file (missing 'ply' magic)");

  PlyHeader header;
  bool have_format = false;
  std::vector<std::string_view> tok;
  while (lines.next(line)) {
    const size_t n = lines.line();
    splitWhitespace(line, tok);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "format") {
      if (tok.size() != 3) throw atLine(path, n, "malformed format line (expected 'format <encoding> 1.0')");
      if (tok[1] == "ascii")
        header.encoding = PlyEncoding::Ascii;
      else if (tok[1] == "binary_little_endian")
        header.encoding = PlyEncoding::BinaryLittleEndian;
      else if (tok[1] == "binary_big_endian")
        header.encoding = PlyEncoding::BinaryBigEndian;
      else
        throw atLine(path, n, "unknown PLY format " + quoted(tok[1]));
      if (tok[2] != "1.0") throw atLine(path, n, "unsupported PLY version " + quoted(tok[2]));
      have_format = true;
    } else if (key == "comment") {
      if (auto v = viewpointComment(tok, 1)) header.viewpoint = v;
      if (auto b = lostBetaComment(tok, 1)) header.lost_beta_rad.insert(header.lost_beta_rad.end(), b->begin(), b->end());
      double range = 0;
      if (tok.size() == 3 && tok[1] == "scanner_range_m" && parseNumber(tok[2], range) == Parsed::Ok &&
          std::isfinite(range) && range > 0)
        header.scanner_range_m = range;
    } else if (key == "obj_info") {
      continue;
    } else if (key == "element") {
      PlyElement e;
      if (tok.size() != 3 || !parseInteger(tok[2], e.count))
        throw atLine(path, n, "malformed element line (expected 'element <name> <count>')");
      e.name = std::string(tok[1]);
      e.line = n;
      header.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (header.elements.empty()) throw atLine(path, n, "property before any element");
      PlyProperty p;
      p.line = n;
      if (tok.size() >= 2 && tok[1] == "list") {
        if (tok.size() != 5)
          throw atLine(path, n, "malformed list property (expected 'property list <count type> <item type> <name>')");
        const auto count_type = plyScalar(tok[2]);
        const auto item_type = plyScalar(tok[3]);
        if (!count_type) throw atLine(path, n, "unknown PLY property type " + quoted(tok[2]));
        if (!item_type) throw atLine(path, n, "unknown PLY property type " + quoted(tok[3]));
        if (!isIntegerScalar(*count_type))
          throw atLine(path, n, "list count type must be an integer type (got " + quoted(tok[2]) + ")");
        p.is_list = true;
        p.count_type = *count_type;
        p.type = *item_type;
        p.name = std::string(tok[4]);
      } else {
        if (tok.size() != 3) throw atLine(path, n, "malformed property line (expected 'property <type> <name>')");
        const auto type = plyScalar(tok[1]);
        if (!type) throw atLine(path, n, "unknown PLY property type " + quoted(tok[1]));
        p.type = *type;
        p.name = std::string(tok[2]);
      }
      header.elements.back().properties.push_back(std::move(p));
    } else if (key == "end_header") {
      header.end_header_line = n;
      header.data_offset = static_cast<size_t>(lines.position() - buf.data());
      if (!have_format) throw atLine(path, n, "PLY header has no 'format' line");
      return header;
    } else {
      throw atLine(path, n, "unknown PLY header keyword " + quoted(key));
    }
  }
  throw atLine(path, lines.line(), "truncated PLY header (no 'end_header')");
}

FileError truncatedAtByte(const std::string& path, size_t byte, const PlyElement& e, uint64_t got) {
  return atByte(path, byte,
                "truncated data (expected " + std::to_string(e.count) + " " + elementNoun(e) + ", got " +
                    std::to_string(got) + ")");
}

FileError truncatedAtLine(const std::string& path, size_t line, const PlyElement& e, uint64_t got) {
  return atLine(path, line,
                "truncated data (expected " + std::to_string(e.count) + " " + elementNoun(e) + ", got " +
                    std::to_string(got) + ")");
}

size_t skipBinaryList(const std::string& path, const std::string& buf, size_t pos, const PlyProperty& p, bool swap,
                      const PlyElement& e, uint64_t item) {
  const size_t count_size = scalarSize(p.count_type);
  if (buf.size() - pos < count_size) throw truncatedAtByte(path, buf.size(), e, item);
  const double count = loadScalar(buf.data() + pos, p.count_type, swap);
  if (count < 0) throw atByte(path, pos, "negative list length " + std::to_string(static_cast<long long>(count)));
  pos += count_size;
  const uint64_t bytes = static_cast<uint64_t>(count) * scalarSize(p.type);
  if (buf.size() - pos < bytes) throw truncatedAtByte(path, buf.size(), e, item);
  return pos + static_cast<size_t>(bytes);
}

size_t skipBinaryElement(const std::string& path, const std::string& buf, size_t pos, const PlyElement& e, bool swap) {
  if (!e.hasLists()) {
    const size_t stride = e.fixedSize();
    const size_t left = buf.size() - pos;
    if (stride > 0 && e.count > left / stride) throw truncatedAtByte(path, buf.size(), e, left / stride);
    return pos + static_cast<size_t>(e.count) * stride;
  }
  for (uint64_t i = 0; i < e.count; ++i)
    for (const auto& p : e.properties) {
      if (p.is_list) {
        pos = skipBinaryList(path, buf, pos, p, swap, e, i);
      } else {
        const size_t n = scalarSize(p.type);
        if (buf.size() - pos < n) throw truncatedAtByte(path, buf.size(), e, i);
        pos += n;
      }
    }
  return pos;
}

}  // namespace sailshape::detail
