// Identifiers of SLAM entities. Entities refer to each other by id, never by raw pointer.
#pragma once

#include <cstdint>
#include <limits>

namespace dynorb {

using FrameId = uint64_t;
using KeyframeId = uint64_t;
using LandmarkId = uint64_t;

constexpr KeyframeId kNoKeyframe = std::numeric_limits<uint64_t>::max();
constexpr LandmarkId kNoLandmark = std::numeric_limits<uint64_t>::max();

}  // namespace dynorb
