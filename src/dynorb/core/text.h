// Small text helpers shared by the parsers of model files (darknet cfg, class-name lists).
#pragma once

#include <string>

namespace dynorb {

// `s` without leading and trailing blanks (space, tab, CR, LF); "" when it has nothing else.
inline std::string TrimBlanks(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r\n") - begin + 1);
}

}  // namespace dynorb
