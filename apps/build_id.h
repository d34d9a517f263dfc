// Identity of the running dynorb executable: FNV-1a 64 of its bytes (/proc/self/exe), computed
// once. stats.json records it, and `dynorb bench` resumes a run only when its stats.json was
// written by this very executable — results of an older build are run again, not reused.
#pragma once

#include <string>

namespace dynorb {

// "fnv1a64:<16 hex digits>", or "unknown" when the executable cannot be read.
const std::string& BuildId();

}  // namespace dynorb
