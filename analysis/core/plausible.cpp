#include "analysis/core/plausible.hpp"

#include <cmath>
#include <cstdio>

namespace sailshape {

namespace {

std::string metres(double v) {
  char b[64];
  if (std::abs(v) >= 1e6 || (v != 0 && std::abs(v) < 1e-3)) std::snprintf(b, sizeof(b), "%.3g", v);
  else std::snprintf(b, sizeof(b), "%.1f", v);
  return b;
}

}  // namespace

std::optional<std::string> implausibleCoordinates(const std::vector<Vec3>& points, const std::string& what) {
  double farthest = 0;
  for (const Vec3& p : points) {
    if (!p.allFinite()) return what + " has a non-finite coordinate";
    farthest = std::max(farthest, p.norm());
  }
  if (farthest <= kFarthestSampleM) return std::nullopt;
  const std::string reach = "a scan reaches at most " + metres(kFarthestSampleM) + " m from its boat's origin (" +
                            metres(kLongestScannerRangeM) + " m of scanner range from a unit on a " +
                            metres(kLongestBoatM) + " m boat)";
  if (farthest / 1000.0 <= kFarthestSampleM)
    return what + " looks like millimetres: it reaches " + metres(farthest) + " units from the origin and " + reach +
           "; write it in metres";
  return what + " reaches " + metres(farthest) + " m from the origin, and " + reach +
         ": not a scan in metres in the boat's or the scanner's frame";
}

std::optional<std::string> implausibleLength(double value_m, const std::string& name) {
  if (!std::isfinite(value_m)) return name + " is not a number";
  // A length measured on one scene lies within it: twice the farthest sample.
  if (value_m < 0 || value_m > 2 * kFarthestSampleM)
    return name + " of " + metres(value_m) + " m is no sail's (a scene spans at most " +
           metres(2 * kFarthestSampleM) + " m)";
  return std::nullopt;
}

std::optional<std::string> implausibleArea(double value_m2, const std::string& name) {
  if (!std::isfinite(value_m2)) return name + " is not a number";
  const double largest = 4 * kFarthestSampleM * kFarthestSampleM;  // the scene's square
  if (value_m2 < 0 || value_m2 > largest)
    return name + " of " + metres(value_m2) + " m² is no sail's (a scene's square is " + metres(largest) + " m²)";
  return std::nullopt;
}

}  // namespace sailshape
