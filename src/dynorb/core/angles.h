// Angle constants and degree <-> radian conversions, shared so that no module defines its own π.
// The forms are fixed: `DegToRad(d)` is `d * kPi / 180` and `RadToDeg(r)` is `r * 180 / kPi`
// (evaluated left to right), `kRadPerDeg` / `kDegPerRad` the folded factors; callers that
// multiplied by a folded factor keep doing so, so every result is bit-identical to before.
#pragma once

namespace dynorb {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kRadPerDeg = kPi / 180.0;
inline constexpr double kDegPerRad = 180.0 / kPi;

constexpr double DegToRad(double deg) { return deg * kPi / 180.0; }
constexpr double RadToDeg(double rad) { return rad * 180.0 / kPi; }

}  // namespace dynorb
