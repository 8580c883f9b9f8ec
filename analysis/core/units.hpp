#pragma once
// Angle units, named by what they convert: an angle in degrees times kRadPerDeg is in radians.

namespace sailshape {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kRadPerDeg = kPi / 180.0;  // rad per degree
inline constexpr double kDegPerRad = 180.0 / kPi;  // degrees per rad

}  // namespace sailshape
