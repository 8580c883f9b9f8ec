#include "analysis/io/cloud_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string_view>

#include <lzf.h>

#include "analysis/core/errors.hpp"
#include "analysis/core/plausible.hpp"
#include "analysis/io/ply_format.hpp"
#include "analysis/io/text_scan.hpp"

namespace sailshape {

using namespace detail;

namespace {

FileError unknownExtension(const std::string& path) {
  return fileError(path, "unknown cloud file extension '" + std::filesystem::path(path).extension().string() +
                             "' (expected .ply .pcd .xyz .txt .csv)");
}

// ---------------------------------------------------------------------------
// Building the cloud: roles of columns/properties, NaN dropping, final checks.

enum Role : int { kX, kY, kZ, kIntensity, kAlpha, kBeta, kRoleCount, kNoRole = -1 };

const char* const kAxisNames[3] = {"x", "y", "z"};

int roleOf(std::string_view name) {
  const std::string n = lowercase(name);
  if (n == "x") return kX;
  if (n == "y") return kY;
  if (n == "z") return kZ;
  if (n == "intensity" || n == "scalar_intensity" || n == "reflectance") return kIntensity;
  if (n == "alpha_rad") return kAlpha;
  if (n == "beta_rad") return kBeta;
  return kNoRole;
}

// Roles per column/property; a name seen twice keeps its first column.
std::vector<int> assignRoles(const std::vector<std::string_view>& names) {
  std::vector<int> roles(names.size(), kNoRole);
  std::array<bool, kRoleCount> taken{};
  for (size_t i = 0; i < names.size(); ++i) {
    const int r = roleOf(names[i]);
    if (r != kNoRole && !taken[r]) {
      roles[i] = r;
      taken[r] = true;
    }
  }
  return roles;
}

std::array<bool, kRoleCount> presentRoles(const std::vector<int>& roles) {
  std::array<bool, kRoleCount> present{};
  for (int r : roles)
    if (r != kNoRole) present[r] = true;
  return present;
}

class CloudBuilder {
 public:
  CloudBuilder(const std::array<bool, kRoleCount>& present, size_t expected_points) : present_(present) {
    cloud_.points.reserve(expected_points);
    if (present_[kIntensity]) cloud_.intensity.reserve(expected_points);
    if (present_[kAlpha]) cloud_.alpha_rad.reserve(expected_points);
    if (present_[kBeta]) cloud_.beta_rad.reserve(expected_points);
  }

  // v indexed by Role; NaN coordinates drop the point (invalid returns).
  void add(const double (&v)[kRoleCount]) {
    ++seen_;
    if (std::isnan(v[kX]) || std::isnan(v[kY]) || std::isnan(v[kZ])) {
      ++dropped_;
      return;
    }
    cloud_.points.emplace_back(v[kX], v[kY], v[kZ]);
    if (present_[kIntensity]) cloud_.intensity.push_back(static_cast<float>(v[kIntensity]));
    if (present_[kAlpha]) cloud_.alpha_rad.push_back(v[kAlpha]);
    if (present_[kBeta]) cloud_.beta_rad.push_back(v[kBeta]);
  }

  CloudReadResult finish(const std::string& path, std::string format, const std::optional<Vec3>& viewpoint,
                         std::vector<double> lost_beta_rad = {}, double scanner_range_m = 0) {
    if (seen_ == 0) throw fileError(path, "no points");
    if (cloud_.empty())
      throw fileError(path, "no finite points (all " + std::to_string(seen_) + " points have NaN coordinates)");
    CloudReadResult result;
    cloud_.viewpoint = viewpoint;
    cloud_.lost_beta_rad = std::move(lost_beta_rad);
    cloud_.scanner_range_m = scanner_range_m;
    result.cloud = std::move(cloud_);
    result.format = std::move(format);
    result.dropped_nan_points = dropped_;
    if (dropped_ > 0) result.warnings.push_back("dropped " + std::to_string(dropped_) + " points with NaN coordinates");
    return result;
  }

 private:
  std::array<bool, kRoleCount> present_;
  Cloud cloud_;
  size_t seen_ = 0;
  size_t dropped_ = 0;
};

// Capacity to reserve: what the header promises, but no more than the data could hold.
size_t reserveFor(uint64_t promised, size_t bytes_left, size_t min_bytes_per_point) {
  return static_cast<size_t>(std::min<uint64_t>(promised, bytes_left / std::max<size_t>(min_bytes_per_point, 1)));
}

// ---------------------------------------------------------------------------
// PLY

void readPlyBinaryVertices(const std::string& path, const std::string& buf, size_t pos, bool swap,
                           const PlyElement& vertex, const std::vector<int>& roles, CloudBuilder& builder) {
  const char* base = buf.data();
  const size_t size = buf.size();
  double v[kRoleCount] = {};
  const auto& props = vertex.properties;
  for (uint64_t i = 0; i < vertex.count; ++i) {
    for (size_t k = 0; k < props.size(); ++k) {
      const PlyProperty& p = props[k];
      if (p.is_list) {
        pos = skipBinaryList(path, buf, pos, p, swap, vertex, i);
        continue;
      }
      const size_t n = scalarSize(p.type);
      if (size - pos < n) throw truncatedAtByte(path, size, vertex, i);
      const int role = roles[k];
      if (role != kNoRole) {
        const double x = loadScalar(base + pos, p.type, swap);
        if (role <= kZ && std::isinf(x))
          throw atByte(
              path, pos,
              "infinite coordinate (" + std::string(kAxisNames[role]) + " of vertex " + std::to_string(i) + ")");
        v[role] = x;
      }
      pos += n;
    }
    builder.add(v);
  }
}

void readPlyAsciiVertices(const std::string& path, const std::string& buf, const PlyHeader& header, size_t vertex_index,
                          const std::vector<int>& roles, CloudBuilder& builder) {
  LineReader lines(buf.data() + header.data_offset, buf.data() + buf.size(), header.end_header_line + 1);
  std::string_view line;
  for (size_t e = 0; e < vertex_index; ++e) {
    const PlyElement& skipped = header.elements[e];
    for (uint64_t i = 0; i < skipped.count; ++i)
      if (!lines.nextNonEmpty(line)) throw truncatedAtLine(path, lines.line() + 1, skipped, i);
  }

  const PlyElement& vertex = header.elements[vertex_index];
  const auto& props = vertex.properties;
  const bool has_lists = vertex.hasLists();
  std::vector<std::string_view> tok;
  double v[kRoleCount] = {};
  for (uint64_t i = 0; i < vertex.count; ++i) {
    if (!lines.nextNonEmpty(line)) throw truncatedAtLine(path, lines.line() + 1, vertex, i);
    const size_t n = lines.line();
    splitWhitespace(line, tok);
    if (!has_lists && tok.size() != props.size())
      throw atLine(path, n, "expected " + std::to_string(props.size()) + " values, got " + std::to_string(tok.size()));
    size_t t = 0;
    for (size_t k = 0; k < props.size(); ++k) {
      if (t >= tok.size()) throw atLine(path, n, "too few values (no value for property '" + props[k].name + "')");
      const double x = numberOnLine(path, n, tok[t++]);
      if (props[k].is_list) {
        if (x < 0 || x != std::floor(x)) throw atLine(path, n, "invalid list length " + quoted(tok[t - 1]));
        if (x > static_cast<double>(tok.size() - t))
          throw atLine(path, n, "too few values for list property '" + props[k].name + "'");
        for (size_t j = 0; j < static_cast<size_t>(x); ++j) numberOnLine(path, n, tok[t++]);
        continue;
      }
      const int role = roles[k];
      if (role == kNoRole) continue;
      if (role <= kZ && std::isinf(x)) throw atLine(path, n, "infinite coordinate " + quoted(tok[t - 1]));
      v[role] = x;
    }
    if (t != tok.size())
      throw atLine(path, n, "expected " + std::to_string(t) + " values, got " + std::to_string(tok.size()));
    builder.add(v);
  }
}

CloudReadResult readPly(const std::string& path, const std::string& buf) {
  const PlyHeader header = parsePlyHeader(path, buf);
  size_t vertex_index = header.elements.size();
  for (size_t e = 0; e < header.elements.size(); ++e)
    if (header.elements[e].name == "vertex") {
      vertex_index = e;
      break;
    }
  if (vertex_index == header.elements.size())
    throw atLine(path, header.end_header_line, "PLY header has no 'element vertex'");
  const PlyElement& vertex = header.elements[vertex_index];

  std::vector<std::string_view> names;
  for (const auto& p : vertex.properties) names.emplace_back(p.name);
  const std::vector<int> roles = assignRoles(names);
  for (size_t k = 0; k < roles.size(); ++k)
    if (roles[k] != kNoRole && vertex.properties[k].is_list)
      throw atLine(path, vertex.properties[k].line, "vertex property '" + vertex.properties[k].name + "' is a list");
  const auto present = presentRoles(roles);
  for (int axis = kX; axis <= kZ; ++axis)
    if (!present[axis])
      throw atLine(path, vertex.line, "PLY vertex element has no '" + std::string(kAxisNames[axis]) + "' property");

  const size_t bytes_left = buf.size() - header.data_offset;
  if (header.encoding == PlyEncoding::Ascii) {
    CloudBuilder builder(present, reserveFor(vertex.count, bytes_left, 2 * vertex.properties.size()));
    readPlyAsciiVertices(path, buf, header, vertex_index, roles, builder);
    return builder.finish(path, "ply-ascii", header.viewpoint, header.lost_beta_rad, header.scanner_range_m);
  }

  const bool file_little = header.encoding == PlyEncoding::BinaryLittleEndian;
  const bool swap = file_little != kHostLittleEndian;
  size_t pos = header.data_offset;
  for (size_t e = 0; e < vertex_index; ++e) pos = skipBinaryElement(path, buf, pos, header.elements[e], swap);
  CloudBuilder builder(present, reserveFor(vertex.count, buf.size() - pos, vertex.fixedSize()));
  readPlyBinaryVertices(path, buf, pos, swap, vertex, roles, builder);
  return builder.finish(path, "ply-binary", header.viewpoint, header.lost_beta_rad, header.scanner_range_m);
}

// ---------------------------------------------------------------------------
// PCD (PCL's format, v0.5-0.7)

struct PcdField {
  std::string_view name;
  Scalar type = Scalar::Float32;
  size_t count = 1;
  size_t byte_offset = 0;  // within a binary record
  size_t value_index = 0;  // first of its values on an ascii line
};

struct PcdHeader {
  std::vector<PcdField> fields;
  uint64_t points = 0;
  std::optional<Vec3> viewpoint;
  bool binary = false;
  bool compressed = false;  // binary_compressed: LZF over the fields one after another
  size_t data_offset = 0;
  size_t data_line = 0;
  size_t record_size = 0;
  size_t values_per_point = 0;
};

std::optional<Scalar> pcdScalar(char type, size_t size) {
  switch (type) {
    case 'F':
      if (size == 4) return Scalar::Float32;
      if (size == 8) return Scalar::Float64;
      break;
    case 'I':
      if (size == 1) return Scalar::Int8;
      if (size == 2) return Scalar::Int16;
      if (size == 4) return Scalar::Int32;
      if (size == 8) return Scalar::Int64;
      break;
    case 'U':
      if (size == 1) return Scalar::UInt8;
      if (size == 2) return Scalar::UInt16;
      if (size == 4) return Scalar::UInt32;
      if (size == 8) return Scalar::UInt64;
      break;
  }
  return std::nullopt;
}

PcdHeader parsePcdHeader(const std::string& path, const std::string& buf) {
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::string_view line;
  std::vector<std::string_view> tok;
  std::vector<std::string_view> names, types;
  std::vector<size_t> sizes, counts;
  size_t size_line = 0, type_line = 0, count_line = 0;
  std::optional<uint64_t> width, height, points;
  PcdHeader header;
  bool first_key = true;

  auto unsignedValues = [&](size_t n, const char* key) {
    std::vector<size_t> out;
    for (size_t i = 1; i < tok.size(); ++i) {
      size_t v = 0;
      if (!parseInteger(tok[i], v)) throw atLine(path, n, std::string("invalid ") + key + " value " + quoted(tok[i]));
      out.push_back(v);
    }
    return out;
  };
  auto singleUnsigned = [&](size_t n, const char* key) {
    uint64_t v = 0;
    if (tok.size() != 2 || !parseInteger(tok[1], v))
      throw atLine(path, n, std::string("malformed ") + key + " line (expected one non-negative integer)");
    return v;
  };

  bool have_data = false;
  while (!have_data && lines.next(line)) {
    const size_t n = lines.line();
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    splitWhitespace(t, tok);
    const std::string_view key = tok[0];
    if (key == "VERSION") {
    } else if (key == "FIELDS" || key == "COLUMNS") {
      names.assign(tok.begin() + 1, tok.end());
    } else if (key == "SIZE") {
      sizes = unsignedValues(n, "SIZE");
      size_line = n;
    } else if (key == "TYPE") {
      types.assign(tok.begin() + 1, tok.end());
      type_line = n;
    } else if (key == "COUNT") {
      counts = unsignedValues(n, "COUNT");
      count_line = n;
    } else if (key == "WIDTH") {
      width = singleUnsigned(n, "WIDTH");
    } else if (key == "HEIGHT") {
      height = singleUnsigned(n, "HEIGHT");
    } else if (key == "POINTS") {
      points = singleUnsigned(n, "POINTS");
    } else if (key == "VIEWPOINT") {
      if (tok.size() != 8) throw atLine(path, n, "malformed VIEWPOINT (expected tx ty tz qw qx qy qz)");
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = numberOnLine(path, n, tok[1 + k]);
      const bool origin = v[0] == 0 && v[1] == 0 && v[2] == 0;
      const bool identity = v[3] == 1 && v[4] == 0 && v[5] == 0 && v[6] == 0;
      if (!(origin && identity)) header.viewpoint = Vec3(v[0], v[1], v[2]);
    } else if (key == "DATA") {
      if (tok.size() != 2)
        throw atLine(path, n, "malformed DATA line (expected 'DATA ascii|binary|binary_compressed')");
      if (tok[1] == "ascii")
        header.binary = false;
      else if (tok[1] == "binary")
        header.binary = true;
      else if (tok[1] == "binary_compressed")
        header.binary = header.compressed = true;
      else
        throw atLine(path, n, "unknown PCD DATA type " + quoted(tok[1]));
      header.data_line = n;
      header.data_offset = static_cast<size_t>(lines.position() - buf.data());
      have_data = true;
    } else {
      if (first_key) throw atLine(path, n, "not a PCD file (unknown header keyword " + quoted(key) + ")");
      throw atLine(path, n, "unknown PCD header keyword " + quoted(key));
    }
    first_key = false;
  }
  if (!have_data) throw atLine(path, std::max<size_t>(lines.line(), 1), "truncated PCD header (no DATA line)");

  const size_t dl = header.data_line;
  if (names.empty()) throw atLine(path, dl, "PCD header has no FIELDS");
  if (sizes.size() != names.size())
    throw atLine(
        path, size_line ? size_line : dl,
        "SIZE has " + std::to_string(sizes.size()) + " entries but FIELDS has " + std::to_string(names.size()));
  if (types.size() != names.size())
    throw atLine(
        path, type_line ? type_line : dl,
        "TYPE has " + std::to_string(types.size()) + " entries but FIELDS has " + std::to_string(names.size()));
  if (counts.empty()) counts.assign(names.size(), 1);
  if (counts.size() != names.size())
    throw atLine(
        path, count_line,
        "COUNT has " + std::to_string(counts.size()) + " entries but FIELDS has " + std::to_string(names.size()));

  for (size_t i = 0; i < names.size(); ++i) {
    PcdField f;
    f.name = names[i];
    const auto type = types[i].size() == 1 ? pcdScalar(types[i][0], sizes[i]) : std::nullopt;
    if (!type)
      throw atLine(path, type_line,
                   "unsupported TYPE " + quoted(types[i]) + " with SIZE " + std::to_string(sizes[i]) + " for field " +
                       quoted(names[i]));
    if (counts[i] == 0) throw atLine(path, count_line, "COUNT of field " + quoted(names[i]) + " is 0");
    f.type = *type;
    f.count = counts[i];
    f.byte_offset = header.record_size;
    f.value_index = header.values_per_point;
    header.record_size += sizes[i] * counts[i];
    header.values_per_point += counts[i];
    header.fields.push_back(f);
  }
  if (points)
    header.points = *points;
  else if (width)
    header.points = *width * height.value_or(1);
  else
    throw atLine(path, dl, "PCD header has neither POINTS nor WIDTH");
  return header;
}

// The fields of a binary_compressed PCD, inflated: after the DATA line come the
// compressed and the inflated byte counts (uint32 each, little-endian), then the
// LZF stream of every field's values for all points, field after field.
std::vector<char> inflatePcd(const std::string& path, const std::string& buf, const PcdHeader& header) {
  const size_t at = header.data_offset;
  if (buf.size() - at < 8)
    throw atByte(path, buf.size(), "truncated binary_compressed data (no size words after the DATA line)");
  uint32_t packed = 0, unpacked = 0;
  std::memcpy(&packed, buf.data() + at, 4);
  std::memcpy(&unpacked, buf.data() + at + 4, 4);
  if (!kHostLittleEndian) {
    packed = __builtin_bswap32(packed);
    unpacked = __builtin_bswap32(unpacked);
  }
  const uint64_t expected = header.points * header.record_size;
  if (unpacked != expected)
    throw atByte(path, at + 4,
                 "binary_compressed data inflates to " + std::to_string(unpacked) + " bytes, but " +
                     std::to_string(header.points) + " points of " + std::to_string(header.record_size) +
                     " bytes need " + std::to_string(expected));
  if (packed > buf.size() - at - 8)
    throw atByte(path, buf.size(),
                 "truncated binary_compressed data (" + std::to_string(packed) + " compressed bytes announced, " +
                     std::to_string(buf.size() - at - 8) + " in the file)");
  std::vector<char> out(unpacked);
  if (unpacked == 0) return out;
  const unsigned got = lzf_decompress(buf.data() + at + 8, packed, out.data(), unpacked);
  if (got != unpacked)
    throw atByte(path, at + 8,
                 "corrupt binary_compressed data (LZF " + std::string(got == 0 ? "stream is invalid" : "stream ended early") +
                     ": " + std::to_string(got) + " of " + std::to_string(unpacked) + " bytes inflated)");
  return out;
}

CloudReadResult readPcd(const std::string& path, const std::string& buf) {
  const PcdHeader header = parsePcdHeader(path, buf);
  std::vector<std::string_view> names;
  for (const auto& f : header.fields) names.push_back(f.name);
  const std::vector<int> roles = assignRoles(names);
  const auto present = presentRoles(roles);
  for (int axis = kX; axis <= kZ; ++axis)
    if (!present[axis])
      throw atLine(path, header.data_line, "PCD FIELDS has no '" + std::string(kAxisNames[axis]) + "' field");

  // (role, field) pairs so the inner loops touch only what they keep.
  std::vector<std::pair<int, const PcdField*>> used;
  for (size_t i = 0; i < roles.size(); ++i)
    if (roles[i] != kNoRole) used.emplace_back(roles[i], &header.fields[i]);

  const size_t bytes_left = buf.size() - header.data_offset;
  double v[kRoleCount] = {};
  if (header.binary) {
    // Plain binary holds one record per point; binary_compressed (PCL's
    // savePCDFileBinaryCompressed) holds, once inflated, each field's values for
    // every point, one field after another.
    const size_t stride = header.record_size;
    std::vector<char> inflated;
    if (header.compressed) inflated = inflatePcd(path, buf, header);
    const char* data = header.compressed ? inflated.data() : buf.data() + header.data_offset;
    const size_t available = header.compressed ? inflated.size() : bytes_left;
    CloudBuilder builder(present, reserveFor(header.points, available, stride));
    if (stride > 0 && header.points > available / stride)
      throw atByte(path, buf.size(),
                   "truncated data (expected " + std::to_string(header.points) + " points, got " +
                       std::to_string(available / stride) + ")");
    auto valueOf = [&](const PcdField& f, uint64_t i) {
      return header.compressed ? data + header.points * f.byte_offset + i * scalarSize(f.type) * f.count
                               : data + i * stride + f.byte_offset;
    };
    const bool swap = !kHostLittleEndian;  // PCL writes little-endian in practice
    for (uint64_t i = 0; i < header.points; ++i) {
      for (const auto& [role, field] : used) {
        const char* p = valueOf(*field, i);
        const double x = loadScalar(p, field->type, swap);
        if (role <= kZ && std::isinf(x)) {
          const std::string what =
              "infinite coordinate (" + std::string(kAxisNames[role]) + " of point " + std::to_string(i) + ")";
          if (header.compressed) throw atLine(path, header.data_line, what + " in the compressed data");
          throw atByte(path, static_cast<size_t>(p - buf.data()), what);
        }
        v[role] = x;
      }
      builder.add(v);
    }
    return builder.finish(path, header.compressed ? "pcd-binary-compressed" : "pcd-binary", header.viewpoint);
  }

  CloudBuilder builder(present, reserveFor(header.points, bytes_left, 2 * header.values_per_point));
  LineReader lines(buf.data() + header.data_offset, buf.data() + buf.size(), header.data_line + 1);
  std::string_view line;
  std::vector<std::string_view> tok;
  for (uint64_t i = 0; i < header.points; ++i) {
    if (!lines.nextNonEmpty(line))
      throw atLine(
          path, lines.line() + 1,
          "truncated data (expected " + std::to_string(header.points) + " points, got " + std::to_string(i) + ")");
    const size_t n = lines.line();
    splitWhitespace(line, tok);
    if (tok.size() != header.values_per_point)
      throw atLine(
          path, n,
          "expected " + std::to_string(header.values_per_point) + " values, got " + std::to_string(tok.size()));
    for (const auto& [role, field] : used) {
      const std::string_view token = tok[field->value_index];
      const double x = numberOnLine(path, n, token);
      if (role <= kZ && std::isinf(x)) throw atLine(path, n, "infinite coordinate " + quoted(token));
      v[role] = x;
    }
    builder.add(v);
  }
  return builder.finish(path, "pcd-ascii", header.viewpoint);
}

// ---------------------------------------------------------------------------
// XYZ / CSV text

std::string_view headerName(std::string_view token) {
  if (token.substr(0, 2) == "//") token.remove_prefix(2);  // CloudCompare writes "//X,Y,Z"
  if (token.size() >= 2 && (token.front() == '"' || token.front() == '\'') && token.back() == token.front())
    token = token.substr(1, token.size() - 2);
  return token;
}

CloudReadResult readText(const std::string& path, const std::string& buf, const char* format) {
  LineReader lines(buf.data(), buf.data() + buf.size());
  std::string_view line;
  std::vector<std::string_view> tok;
  std::vector<std::string_view> comment_tok;
  std::optional<Vec3> viewpoint;

  std::array<int, kRoleCount> column;  // column of each role, -1 when absent
  column.fill(-1);
  size_t needed = 0;
  std::optional<CloudBuilder> builder;  // made once the first line fixes the columns
  double v[kRoleCount] = {};

  while (lines.next(line)) {
    const size_t n = lines.line();
    const std::string_view t = trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      splitWhitespace(t.substr(1), comment_tok);
      if (auto vp = viewpointComment(comment_tok, 0)) viewpoint = vp;
      continue;
    }
    splitFields(t, tok);

    if (!builder) {
      const bool is_header = std::none_of(tok.begin(), tok.end(), [](std::string_view s) {
        double x;
        return parseNumber(s, x) != Parsed::NotANumber;
      });
      if (is_header) {
        std::vector<std::string_view> names;
        for (auto s : tok) names.push_back(headerName(s));
        const std::vector<int> roles = assignRoles(names);
        for (size_t c = 0; c < roles.size(); ++c)
          if (roles[c] != kNoRole) column[roles[c]] = static_cast<int>(c);
        for (int axis = kX; axis <= kZ; ++axis)
          if (column[axis] < 0) throw atLine(path, n, "header has no '" + std::string(kAxisNames[axis]) + "' column");
      } else {
        column[kX] = 0;
        column[kY] = 1;
        column[kZ] = 2;
        if (tok.size() >= 4) column[kIntensity] = 3;
      }
      std::array<bool, kRoleCount> present{};
      for (int r = 0; r < kRoleCount; ++r) {
        present[r] = column[r] >= 0;
        needed = std::max<size_t>(needed, static_cast<size_t>(column[r] + 1));
      }
      builder.emplace(present, static_cast<size_t>(std::count(buf.begin(), buf.end(), '\n')) + 1);
      if (is_header) continue;
    }

    if (tok.size() < needed)
      throw atLine(path, n,
                   "expected at least " + std::to_string(needed) + " values, got " + std::to_string(tok.size()));
    for (int r = 0; r < kRoleCount; ++r) {
      if (column[r] < 0) continue;
      const std::string_view token = tok[static_cast<size_t>(column[r])];
      if (token.empty()) throw atLine(path, n, "empty value in column " + std::to_string(column[r] + 1));
      const double x = numberOnLine(path, n, token);
      if (r <= kZ && std::isinf(x)) throw atLine(path, n, "infinite coordinate " + quoted(token));
      v[r] = x;
    }
    builder->add(v);
  }
  if (!builder) throw fileError(path, "no points");
  return builder->finish(path, format, viewpoint);
}

// ---------------------------------------------------------------------------
// Writing

void checkAttribute(size_t size, const char* name, size_t n_points) {
  if (size != 0 && size != n_points)
    throw InvalidInput("[writeCloud] " + std::string(name) + " has " + std::to_string(size) + " values for " +
                       std::to_string(n_points) + " points");
}

struct Columns {
  bool intensity, alpha, beta;
};

std::vector<const char*> columnNames(const Columns& c) {
  std::vector<const char*> names = {"x", "y", "z"};
  if (c.intensity) names.push_back("intensity");
  if (c.alpha) names.push_back("alpha_rad");
  if (c.beta) names.push_back("beta_rad");
  return names;
}

// One point as text, separated by `sep`.
void appendPointText(std::string& out, const Cloud& cloud, const Columns& c, size_t i, char sep) {
  const Vec3& p = cloud.points[i];
  appendNumber(out, p.x());
  out += sep;
  appendNumber(out, p.y());
  out += sep;
  appendNumber(out, p.z());
  if (c.intensity) {
    out += sep;
    appendNumber(out, cloud.intensity[i]);
  }
  if (c.alpha) {
    out += sep;
    appendNumber(out, cloud.alpha_rad[i]);
  }
  if (c.beta) {
    out += sep;
    appendNumber(out, cloud.beta_rad[i]);
  }
  out += '\n';
}

// Records of float64 x y z, float32 intensity, float64 alpha_rad beta_rad (the ones present), little-endian.
void appendPointsBinary(std::string& out, const Cloud& cloud, const Columns& c) {
  const size_t stride = 24 + (c.intensity ? 4 : 0) + (c.alpha ? 8 : 0) + (c.beta ? 8 : 0);
  out.reserve(out.size() + stride * cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    appendLittleEndian(out, p.x());
    appendLittleEndian(out, p.y());
    appendLittleEndian(out, p.z());
    if (c.intensity) appendLittleEndian(out, cloud.intensity[i]);
    if (c.alpha) appendLittleEndian(out, cloud.alpha_rad[i]);
    if (c.beta) appendLittleEndian(out, cloud.beta_rad[i]);
  }
}

void appendViewpointNumbers(std::string& out, const Vec3& v) {
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    appendNumber(out, v[k]);
  }
}

std::string plyContent(const Cloud& cloud, const Columns& c, bool binary) {
  std::string out = "ply\nformat ";
  out += binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment written by sailshape\n";
  if (cloud.viewpoint) {
    out += "comment viewpoint";
    appendViewpointNumbers(out, *cloud.viewpoint);
    out += '\n';
  }
  if (cloud.scanner_range_m > 0) {
    out += "comment scanner_range_m ";
    appendNumber(out, cloud.scanner_range_m);
    out += '\n';
  }
  // Ten to a line: a long sweep may lose many.
  for (size_t i = 0; i < cloud.lost_beta_rad.size(); i += 10) {
    out += "comment lost_beta_rad";
    for (size_t k = i; k < std::min(i + 10, cloud.lost_beta_rad.size()); ++k) {
      out += ' ';
      appendNumber(out, cloud.lost_beta_rad[k]);
    }
    out += '\n';
  }
  out += "element vertex " + std::to_string(cloud.size()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (c.intensity) out += "property float intensity\n";
  if (c.alpha) out += "property double alpha_rad\n";
  if (c.beta) out += "property double beta_rad\n";
  out += "end_header\n";

  if (!binary) {
    for (size_t i = 0; i < cloud.size(); ++i) appendPointText(out, cloud, c, i, ' ');
    return out;
  }
  appendPointsBinary(out, cloud, c);
  return out;
}

std::string pcdContent(const Cloud& cloud, const Columns& c, bool binary) {
  const auto names = columnNames(c);
  std::string fields, size, type, count;
  for (const char* name : names) {
    const bool is_intensity = std::strcmp(name, "intensity") == 0;
    fields += std::string(" ") + name;
    size += is_intensity ? " 4" : " 8";
    type += " F";
    count += " 1";
  }
  std::string out = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  out += "FIELDS" + fields + "\nSIZE" + size + "\nTYPE" + type + "\nCOUNT" + count + "\n";
  out += "WIDTH " + std::to_string(cloud.size()) + "\nHEIGHT 1\nVIEWPOINT";
  appendViewpointNumbers(out, cloud.viewpoint.value_or(Vec3::Zero()));
  out += " 1 0 0 0\nPOINTS " + std::to_string(cloud.size()) + "\nDATA ";
  out += binary ? "binary\n" : "ascii\n";

  if (!binary) {
    for (size_t i = 0; i < cloud.size(); ++i) appendPointText(out, cloud, c, i, ' ');
    return out;
  }
  appendPointsBinary(out, cloud, c);
  return out;
}

// CSV always names its columns; XYZ only when there is more than x y z [intensity], which a
// reader maps without a header.
std::string textContent(const Cloud& cloud, const Columns& c, bool csv) {
  const char sep = csv ? ',' : ' ';
  std::string out;
  if (cloud.viewpoint) {
    out += "# viewpoint";
    appendViewpointNumbers(out, *cloud.viewpoint);
    out += '\n';
  }
  if (csv || c.alpha || c.beta) {
    const auto names = columnNames(c);
    for (size_t i = 0; i < names.size(); ++i) {
      if (i > 0) out += sep;
      out += names[i];
    }
    out += '\n';
  }
  for (size_t i = 0; i < cloud.size(); ++i) appendPointText(out, cloud, c, i, sep);
  return out;
}

}  // namespace

CloudReadResult readCloud(const std::string& path) {
  const std::string ext = extensionOf(path);
  const bool known = ext == ".ply" || ext == ".pcd" || ext == ".xyz" || ext == ".txt" || ext == ".csv";
  if (!known) throw unknownExtension(path);
  const std::string buf = readWholeFile(path);
  CloudReadResult read = ext == ".ply"   ? readPly(path, buf)
                         : ext == ".pcd" ? readPcd(path, buf)
                                         : readText(path, buf, ext == ".csv" ? "csv" : "xyz");
  if (auto why = implausibleCoordinates(read.cloud.points, "the cloud")) throw FileError(path + ": " + *why);
  return read;
}

void writeCloud(const std::string& path, const Cloud& cloud, CloudFormat format) {
  const size_t n = cloud.size();
  checkAttribute(cloud.intensity.size(), "intensity", n);
  checkAttribute(cloud.alpha_rad.size(), "alpha_rad", n);
  checkAttribute(cloud.beta_rad.size(), "beta_rad", n);
  const Columns c{!cloud.intensity.empty(), !cloud.alpha_rad.empty(), !cloud.beta_rad.empty()};

  if (format == CloudFormat::Auto) {
    const std::string ext = extensionOf(path);
    if (ext == ".ply")
      format = CloudFormat::PlyBinary;
    else if (ext == ".pcd")
      format = CloudFormat::PcdBinary;
    else if (ext == ".csv")
      format = CloudFormat::Csv;
    else if (ext == ".xyz" || ext == ".txt")
      format = CloudFormat::Xyz;
    else
      throw unknownExtension(path);
  }

  std::string content;
  switch (format) {
    case CloudFormat::PlyAscii:
      content = plyContent(cloud, c, false);
      break;
    case CloudFormat::PlyBinary:
      content = plyContent(cloud, c, true);
      break;
    case CloudFormat::PcdAscii:
      content = pcdContent(cloud, c, false);
      break;
    case CloudFormat::PcdBinary:
      content = pcdContent(cloud, c, true);
      break;
    case CloudFormat::Xyz:
      content = textContent(cloud, c, false);
      break;
    case CloudFormat::Csv:
      content = textContent(cloud, c, true);
      break;
    case CloudFormat::Auto:
      break;
  }
  writeWholeFile(path, content);
}

}  // namespace sailshape
