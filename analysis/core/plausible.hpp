#pragma once
// What a measured scene can span. Every sample of a scan lies within the scanner's
// range of its unit (SPEC §3: LMS511 0.7-80 m, the longest sailshape reads), and the
// units stand on one boat or in one tunnel, whose frame (SPEC §2, origin at the mast
// foot) or whose own scanner frame the cloud is in. A coordinate beyond that reach is
// not a measurement in metres: a cloud in millimetres, in a survey frame, or garbage.
#include <optional>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"

namespace sailshape {

// The longest range of a supported scanner (SPEC §3, LMS511), m.
inline constexpr double kLongestScannerRangeM = 80.0;
// The largest sailing yachts are under 100 m long: units anywhere on one stand within
// this of its mast foot.
inline constexpr double kLongestBoatM = 100.0;
// How far from the frame's origin a measured sample can lie: a unit at the far end of
// the boat, seeing as far as its range, m.
inline constexpr double kFarthestSampleM = kLongestBoatM + kLongestScannerRangeM;

// Why `points` cannot be a scan in metres, or nothing when they can: the farthest
// point's distance from the origin, named as millimetres when the same cloud read in
// millimetres would lie within reach. `what` names the cloud ("the cloud", a file).
std::optional<std::string> implausibleCoordinates(const std::vector<Vec3>& points, const std::string& what);

// A reported length (an edge, a chord) or area that no measured sail can have, or a
// non-finite one: the reason, or nothing. `name` and `unit` ("m", "m²") for the message.
std::optional<std::string> implausibleLength(double value_m, const std::string& name);
std::optional<std::string> implausibleArea(double value_m2, const std::string& name);

}  // namespace sailshape
