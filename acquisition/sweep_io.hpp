#pragma once
// Raw sweep samples on disk (what `sailshape scan` writes beside the cloud and
// `sailshape scanner calibrate` reads): CSV with the header
// "range_m,alpha_rad,beta_rad,rssi,time_s", one sample per line.
#include <string>
#include <vector>

#include "acquisition/sweep.hpp"

namespace sailshape {

// Throws FileError when the file exists already (stored data is never overwritten) or cannot be written.
void writeSweepSamples(const std::string& path, const std::vector<SweepPoint>& samples);
// Throws FileError naming the file and line for a missing file, a wrong header or a malformed line.
std::vector<SweepPoint> readSweepSamples(const std::string& path);

}  // namespace sailshape
