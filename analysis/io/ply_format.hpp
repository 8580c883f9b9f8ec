#pragma once
// Shared by cloud_io.cpp and mesh_io.cpp: binary scalars (PLY and PCD types,
// either byte order) and the PLY header with its element/property layout.
// Internal to analysis/.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/errors.hpp"

namespace sailshape::detail {

// ---------------------------------------------------------------------------
// Binary scalars.

enum class Scalar : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

inline size_t scalarSize(Scalar t) {
  switch (t) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Int64:
    case Scalar::UInt64:
    case Scalar::Float64:
      return 8;
  }
  return 0;
}

constexpr bool kHostLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

// A T stored at p (unaligned), byte-reversed when `swap`.
template <typename T>
T loadAs(const char* p, bool swap) {
  T v;
  if (!swap) {
    std::memcpy(&v, p, sizeof(T));
  } else {
    char b[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) b[i] = p[sizeof(T) - 1 - i];
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

// Inline: called once per stored value in the binary readers' inner loops.
inline double loadScalar(const char* p, Scalar t, bool swap) {
  switch (t) {
    case Scalar::Int8:
      return loadAs<int8_t>(p, false);
    case Scalar::UInt8:
      return loadAs<uint8_t>(p, false);
    case Scalar::Int16:
      return loadAs<int16_t>(p, swap);
    case Scalar::UInt16:
      return loadAs<uint16_t>(p, swap);
    case Scalar::Int32:
      return loadAs<int32_t>(p, swap);
    case Scalar::UInt32:
      return loadAs<uint32_t>(p, swap);
    case Scalar::Int64:
      return static_cast<double>(loadAs<int64_t>(p, swap));
    case Scalar::UInt64:
      return static_cast<double>(loadAs<uint64_t>(p, swap));
    case Scalar::Float32:
      return loadAs<float>(p, swap);
    case Scalar::Float64:
      return loadAs<double>(p, swap);
  }
  return 0;
}

// Little-endian on disk whatever the host.
template <typename T>
void appendLittleEndian(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (!kHostLittleEndian) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

// ---------------------------------------------------------------------------
// PLY header.

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::Float32;
  bool is_list = false;
  Scalar count_type = Scalar::UInt8;
  size_t line = 0;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  size_t line = 0;

  bool hasLists() const {
    return std::any_of(properties.begin(), properties.end(), [](const PlyProperty& p) { return p.is_list; });
  }
  size_t fixedSize() const {
    size_t n = 0;
    for (const auto& p : properties) n += scalarSize(p.type);
    return n;
  }
};

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::optional<Vec3> viewpoint;  // from a "comment viewpoint X Y Z" line
  std::vector<double> lost_beta_rad;  // from "comment lost_beta_rad B1 B2 ..." lines
  double scanner_range_m = 0;         // from a "comment scanner_range_m R" line (0: none)
  size_t data_offset = 0;         // first byte after "end_header\n"
  size_t end_header_line = 0;     // line number of end_header
};

bool isIntegerScalar(Scalar t);

// "viewpoint X Y Z" from `first` on (after a comment marker): the scanner origin, when the three
// values are finite numbers.
std::optional<Vec3> viewpointComment(const std::vector<std::string_view>& tokens, size_t first);
// "lost_beta_rad B1 B2 ..." from `first` on: the β of scan lines a sweep lost
// (Cloud::lost_beta_rad), when every value is a finite number.
std::optional<std::vector<double>> lostBetaComment(const std::vector<std::string_view>& tokens, size_t first);

// Throws FileError naming the line of the first malformed header line.
PlyHeader parsePlyHeader(const std::string& path, const std::string& buf);

// ---------------------------------------------------------------------------
// PLY data.

// "truncated data (expected 10 vertices, got 3)" at a byte or a line.
FileError truncatedAtByte(const std::string& path, size_t byte, const PlyElement& e, uint64_t got);
FileError truncatedAtLine(const std::string& path, size_t line, const PlyElement& e, uint64_t got);

// Steps over one binary list property of item `item`; returns the position after it.
size_t skipBinaryList(const std::string& path, const std::string& buf, size_t pos, const PlyProperty& p, bool swap,
                      const PlyElement& e, uint64_t item);

// Steps over all items of a binary element; returns the position after them.
size_t skipBinaryElement(const std::string& path, const std::string& buf, size_t pos, const PlyElement& e, bool swap);

}  // namespace sailshape::detail
