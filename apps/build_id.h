// Identity of the running dynorb executable: FNV-1a 64 of its bytes (/proc/self/exe, in 8-byte
// words), computed once. stats.json records it, and `dynorb bench` resumes a run only when its
// stats.json was written by this very executable — results of an older build are run again.
#pragma once

#include <string>

namespace dynorb {

// "fnv1a64:<16 hex digits>", or kUnknownBuildId when the executable cannot be read (then no
// result is ever resumed).
const std::string& BuildId();
inline constexpr const char* kUnknownBuildId = "unknown";

}  // namespace dynorb
