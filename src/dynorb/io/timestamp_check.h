// Timestamps read from lists and trajectories are seconds: beyond +-1e12 s (30,000 years) a value
// is not a timestamp, and the outputs written with it (%.6f) would not fit their lines.
#pragma once

#include <cmath>
#include <string>

#include "dynorb/core/error.h"

namespace dynorb {

inline constexpr double kMaxTimestampS = 1e12;

// Throws InputErrorAt(path, line) naming `text` when |value| > kMaxTimestampS.
inline void CheckTimestampRange(double value, const std::string& text, const std::string& path,
                                int line) {
  if (std::abs(value) <= kMaxTimestampS) return;
  throw InputErrorAt(path, line,
                     "timestamp '" + text + "' is beyond +-1e12 s: not a time in seconds");
}

}  // namespace dynorb
