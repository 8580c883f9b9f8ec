#include "acquisition/sweep_io.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/core/errors.hpp"

namespace sailshape {

namespace {
constexpr const char* kHeader = "range_m,alpha_rad,beta_rad,rssi,time_s";
}

void writeSweepSamples(const std::string& path, const std::vector<SweepPoint>& samples) {
  if (std::filesystem::exists(path)) throw FileError("[writeSweepSamples] " + path + " exists already; not overwritten");
  std::FILE* f = std::fopen(path.c_str(), "wx");
  if (!f) throw FileError("[writeSweepSamples] cannot create " + path);
  bool ok = std::fprintf(f, "%s\n", kHeader) > 0;
  for (const SweepPoint& s : samples)
    ok = ok && std::fprintf(f, "%.4f,%.9f,%.9f,%u,%.6f\n", s.range_m, s.alpha_rad, s.beta_rad,
                            static_cast<unsigned>(s.rssi), s.time_s) > 0;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) throw FileError("[writeSweepSamples] writing " + path + " failed (disk full?)");
}

std::vector<SweepPoint> readSweepSamples(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError("[readSweepSamples] cannot open " + path);
  std::string line;
  if (!std::getline(in, line) || (line != kHeader && line != std::string(kHeader) + "\r"))
    throw FileError("[readSweepSamples] " + path + ": line 1 must be '" + kHeader + "'");
  std::vector<SweepPoint> out;
  size_t number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    SweepPoint s;
    unsigned rssi = 0;
    char extra = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%u,%lf %c", &s.range_m, &s.alpha_rad, &s.beta_rad, &rssi, &s.time_s,
                    &extra) != 5 ||
        rssi > 255 || !(s.range_m > 0))
      throw FileError("[readSweepSamples] " + path + ": line " + std::to_string(number) +
                      " is not 'range_m,alpha_rad,beta_rad,rssi,time_s' with a positive range: '" + line + "'");
    s.rssi = static_cast<uint8_t>(rssi);
    out.push_back(s);
  }
  return out;
}

}  // namespace sailshape
