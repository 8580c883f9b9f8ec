#include "database/cloud_blob.hpp"

#include <zlib.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "database/sqlite.hpp"

namespace sailshape {
namespace {

constexpr char kMagic[4] = {'S', 'S', 'C', '1'};
constexpr uint32_t kHasIntensity = 1;
constexpr uint32_t kHasScanAngles = 2;  // float32 α then β per point (rad)
constexpr uint32_t kHasViewpoint = 4;   // three float64 after the per-point data
constexpr uint32_t kHasLostLines = 8;   // after those, a uint32 count and as many float64 β (rad)
constexpr uint32_t kKnownFlags = kHasIntensity | kHasScanAngles | kHasViewpoint | kHasLostLines;
constexpr size_t kHeader = 4 + 8 + 4;  // magic, point count, flags

template <typename T>
void put(std::vector<uint8_t>& out, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}

std::string hex(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%x", v);
  return buf;
}

}  // namespace

std::vector<uint8_t> compressCloud(const Cloud& cloud) {
  const size_t n = cloud.size();
  const bool intensity = cloud.hasIntensity() && cloud.intensity.size() == n;
  const bool angles = cloud.hasScanAngles() && cloud.alpha_rad.size() == n && cloud.beta_rad.size() == n;
  const bool lost = !cloud.lost_beta_rad.empty();
  const uint32_t flags = (intensity ? kHasIntensity : 0) | (angles ? kHasScanAngles : 0) |
                         (cloud.viewpoint ? kHasViewpoint : 0) | (lost ? kHasLostLines : 0);
  std::vector<uint8_t> raw;
  raw.reserve(kHeader + n * (12 + (intensity ? 4 : 0) + (angles ? 8 : 0)) + (cloud.viewpoint ? 24 : 0));
  raw.insert(raw.end(), kMagic, kMagic + 4);
  put<uint64_t>(raw, n);
  put<uint32_t>(raw, flags);
  for (const Vec3& p : cloud.points)
    for (int k = 0; k < 3; ++k) put<float>(raw, static_cast<float>(p[k]));
  if (intensity)
    for (float v : cloud.intensity) put<float>(raw, v);
  // The angles keep the surface's (α, β) triangulation (analysis/surface) for a
  // re-analysis; float32 is 0.2 µrad at π, 6 µm at 30 m.
  if (angles) {
    for (double a : cloud.alpha_rad) put<float>(raw, static_cast<float>(a));
    for (double b : cloud.beta_rad) put<float>(raw, static_cast<float>(b));
  }
  // The scanner's position orients the normals and places the beam's footprint at the edges.
  if (cloud.viewpoint)
    for (int k = 0; k < 3; ++k) put<double>(raw, (*cloud.viewpoint)[k]);
  // The scan lines its sweep lost: a corner beside one may lie a line further out.
  if (lost) {
    put<uint32_t>(raw, static_cast<uint32_t>(cloud.lost_beta_rad.size()));
    for (double b : cloud.lost_beta_rad) put<double>(raw, b);
  }
  // The uncompressed size first, so decompression knows its buffer.
  std::vector<uint8_t> out;
  put<uint64_t>(out, raw.size());
  uLongf len = compressBound(raw.size());
  out.resize(8 + len);
  if (compress2(out.data() + 8, &len, raw.data(), raw.size(), 6) != Z_OK)
    throw DatabaseError("[compressCloud] zlib failed for " + std::to_string(cloud.size()) + " points");
  out.resize(8 + len);
  return out;
}

Cloud decompressCloud(const std::vector<uint8_t>& blob) {
  if (blob.size() < 8) throw DatabaseError("[decompressCloud] blob of " + std::to_string(blob.size()) + " bytes is too short");
  uint64_t raw_size = 0;
  std::memcpy(&raw_size, blob.data(), 8);
  if (raw_size < kHeader || raw_size > (uint64_t(1) << 34))
    throw DatabaseError("[decompressCloud] implausible size " + std::to_string(raw_size));
  std::vector<uint8_t> raw(raw_size);
  uLongf len = raw_size;
  if (uncompress(raw.data(), &len, blob.data() + 8, blob.size() - 8) != Z_OK || len != raw_size ||
      std::memcmp(raw.data(), kMagic, 4) != 0)
    throw DatabaseError("[decompressCloud] not a compressed sailshape cloud (" + std::to_string(blob.size()) + " bytes)");
  uint64_t n = 0;
  uint32_t flags = 0;
  std::memcpy(&n, raw.data() + 4, 8);
  std::memcpy(&flags, raw.data() + 12, 4);
  if (flags & ~kKnownFlags)
    throw DatabaseError("[decompressCloud] cloud flags 0x" + hex(flags) + " are unknown: written by a newer sailshape");
  const uint64_t per_point = 12 + ((flags & kHasIntensity) ? 4 : 0) + ((flags & kHasScanAngles) ? 8 : 0);
  const uint64_t fixed = n > raw_size / per_point ? raw_size + 1 : kHeader + n * per_point + ((flags & kHasViewpoint) ? 24 : 0);
  uint32_t lost = 0;
  if ((flags & kHasLostLines) && fixed + 4 <= raw_size) std::memcpy(&lost, raw.data() + fixed, 4);
  if (fixed > raw_size || raw_size != fixed + ((flags & kHasLostLines) ? 4 + 8 * uint64_t(lost) : 0))
    throw DatabaseError("[decompressCloud] " + std::to_string(n) + " points do not fit " + std::to_string(raw_size) + " bytes");
  Cloud cloud;
  cloud.points.resize(n);
  const uint8_t* p = raw.data() + kHeader;
  for (uint64_t i = 0; i < n; ++i) {
    float xyz[3];
    std::memcpy(xyz, p + 12 * i, 12);
    cloud.points[i] = Vec3(xyz[0], xyz[1], xyz[2]);
  }
  p += 12 * n;
  if (flags & kHasIntensity) {
    cloud.intensity.resize(n);
    std::memcpy(cloud.intensity.data(), p, 4 * n);
    p += 4 * n;
  }
  if (flags & kHasScanAngles) {
    std::vector<float> a(2 * n);
    std::memcpy(a.data(), p, 8 * n);
    cloud.alpha_rad.assign(a.begin(), a.begin() + n);
    cloud.beta_rad.assign(a.begin() + n, a.end());
    p += 8 * n;
  }
  if (flags & kHasViewpoint) {
    double v[3];
    std::memcpy(v, p, 24);
    cloud.viewpoint = Vec3(v[0], v[1], v[2]);
    p += 24;
  }
  if ((flags & kHasLostLines) && lost > 0) {
    cloud.lost_beta_rad.resize(lost);
    std::memcpy(cloud.lost_beta_rad.data(), p + 4, 8 * uint64_t(lost));
  }
  return cloud;
}

}  // namespace sailshape
