#include "database/cloud_blob.hpp"

#include <zlib.h>

#include <cstring>
#include <string>

#include "database/sqlite.hpp"

namespace sailshape {
namespace {

constexpr char kMagic[4] = {'S', 'S', 'C', '1'};
constexpr uint32_t kHasIntensity = 1;
constexpr size_t kHeader = 4 + 8 + 4;  // magic, point count, flags

template <typename T>
void put(std::vector<uint8_t>& out, T v) {
  const auto* p = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), p, p + sizeof(T));
}

}  // namespace

std::vector<uint8_t> compressCloud(const Cloud& cloud) {
  const bool intensity = cloud.hasIntensity() && cloud.intensity.size() == cloud.size();
  std::vector<uint8_t> raw;
  raw.reserve(kHeader + cloud.size() * (intensity ? 16 : 12));
  raw.insert(raw.end(), kMagic, kMagic + 4);
  put<uint64_t>(raw, cloud.size());
  put<uint32_t>(raw, intensity ? kHasIntensity : 0);
  for (const Vec3& p : cloud.points)
    for (int k = 0; k < 3; ++k) put<float>(raw, static_cast<float>(p[k]));
  if (intensity)
    for (float v : cloud.intensity) put<float>(raw, v);
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
  const size_t per_point = (flags & kHasIntensity) ? 16 : 12;
  if (raw_size != kHeader + n * per_point)
    throw DatabaseError("[decompressCloud] " + std::to_string(n) + " points do not fit " + std::to_string(raw_size) + " bytes");
  Cloud cloud;
  cloud.points.resize(n);
  const uint8_t* p = raw.data() + kHeader;
  for (uint64_t i = 0; i < n; ++i) {
    float xyz[3];
    std::memcpy(xyz, p + 12 * i, 12);
    cloud.points[i] = Vec3(xyz[0], xyz[1], xyz[2]);
  }
  if (flags & kHasIntensity) {
    cloud.intensity.resize(n);
    std::memcpy(cloud.intensity.data(), p + 12 * n, 4 * n);
  }
  return cloud;
}

}  // namespace sailshape
