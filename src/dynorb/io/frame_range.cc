#include "dynorb/io/frame_range.h"

#include <algorithm>
#include <exception>

#include "dynorb/core/error.h"

namespace dynorb {

FrameRange ParseFrameRange(const std::string& text, const std::string& what) {
  FrameRange range;
  if (text.empty()) return range;
  const size_t colon = text.find(':');
  if (colon == std::string::npos) {
    throw InputError(what + " expects A:B (e.g. 0:300 or 100:), got '" + text + "'");
  }
  auto parse = [&](const std::string& s) -> std::optional<size_t> {
    if (s.empty()) return std::nullopt;
    size_t pos = 0;
    long long v = -1;
    try {
      v = std::stoll(s, &pos);
    } catch (const std::exception&) {
      pos = 0;
    }
    if (pos != s.size() || v < 0) throw InputError(what + ": not a frame index: '" + s + "'");
    return static_cast<size_t>(v);
  };
  range.first = parse(text.substr(0, colon));
  range.last = parse(text.substr(colon + 1));
  if (range.first && range.last && *range.first >= *range.last) {
    throw InputError(what + " " + text + " selects no frame");
  }
  return range;
}

std::pair<size_t, size_t> SelectFrames(const std::string& text, size_t size,
                                       const std::string& what) {
  const FrameRange range = ParseFrameRange(text, what);
  const size_t first = range.first.value_or(0);
  const size_t last = std::min(range.last.value_or(size), size);
  if (first >= last) {
    throw InputError(what + " " + text + " selects no frame of a " + std::to_string(size) +
                     "-frame sequence");
  }
  return {first, last};
}

}  // namespace dynorb
