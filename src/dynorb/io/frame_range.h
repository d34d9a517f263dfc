// FrameRange: the "A:B" frame selection of `dynorb run --frames` and of a bench suite's
// sequence `frames:` (frames A..B-1; either side may be empty; "" selects every frame).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

namespace dynorb {

struct FrameRange {
  std::optional<size_t> first, last;  // Empty: the sequence's start / end.
};

// Checks the syntax (and that B > A when both are given), without knowing the sequence.
// Throws InputError("<what> expects A:B ..." / "<what>: not a frame index: ..." /
// "<what> A:B selects no frame").
FrameRange ParseFrameRange(const std::string& text, const std::string& what = "--frames");

// [first, last) of a `size`-frame sequence (B clamped to size). Throws InputError when no frame
// is selected.
std::pair<size_t, size_t> SelectFrames(const std::string& text, size_t size,
                                       const std::string& what = "--frames");

}  // namespace dynorb
