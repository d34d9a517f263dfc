// Small text helpers shared by the evaluator's messages, the SVG plot and the HTML report.
// Pure functions; thread-safe.
#pragma once

#include <cstdio>
#include <string>

namespace dynorb {

// Shortest %g form of a number, for error messages ("0.02", "1e-06").
inline std::string ShortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// Escapes &, <, > and " for XML/SVG/HTML text and attribute values.
inline std::string EscapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace dynorb
