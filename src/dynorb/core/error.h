// InputError: the one exception type for bad user input (missing/malformed files, bad options).
// Thrown at the edges (io/, apps/), caught in main(): one clear message, non-zero exit.
// Programming errors use CHECK-style aborts instead; expected outcomes use return values.
#pragma once

#include <stdexcept>
#include <string>

namespace dynorb {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// "file:line: message" helper for parse errors.
inline InputError InputErrorAt(const std::string& file, int line, const std::string& message) {
  return InputError(file + ":" + std::to_string(line) + ": " + message);
}

}  // namespace dynorb
