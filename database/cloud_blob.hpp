#pragma once
// The compressed cloud stored in scans.cloud: zlib over a small header
// ("SSC1", point count, flags) and float32 xyz (metres) plus optional float32
// intensity. float32 keeps ≈ 10 µm at 100 m, far below the sensor's σ (SPEC §3).
#include <cstdint>
#include <vector>

#include "analysis/cloud.hpp"

namespace sailshape {

std::vector<uint8_t> compressCloud(const Cloud& cloud);
// Throws DatabaseError for a blob that is not a compressed cloud or is truncated.
Cloud decompressCloud(const std::vector<uint8_t>& blob);

}  // namespace sailshape
