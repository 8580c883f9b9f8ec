#pragma once
// The compressed cloud stored in scans.cloud: zlib over a small header
// ("SSC1", point count, flags) and float32 xyz (metres), then what the cloud
// has of: float32 intensity, float32 scan angles α and β (rad), the float64
// viewpoint, the float64 β (rad) of the scan lines its sweep lost; a flag per
// part says whether it is there. float32 keeps ≈ 10 µm at 100 m, far below the
// sensor's σ (SPEC §3). A blob without a part reads with that part empty.
#include <cstdint>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

std::vector<uint8_t> compressCloud(const Cloud& cloud);
// Throws DatabaseError for a blob that is not a compressed cloud, is truncated or
// carries flags this version does not know.
Cloud decompressCloud(const std::vector<uint8_t>& blob);

}  // namespace sailshape
