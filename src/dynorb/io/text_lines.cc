#include "dynorb/io/text_lines.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "dynorb/core/error.h"

namespace dynorb {

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string current;
  for (char c : line) {
    if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
      if (!current.empty()) fields.push_back(std::move(current));
      current.clear();
    } else {
      current.push_back(c);
    }
  }
  if (!current.empty()) fields.push_back(std::move(current));
  return fields;
}

void ForEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError("file not found: " + path);
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + path);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    // A UTF-8 byte order mark (some editors write one) is not part of the first line's text.
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    fn(line_no, SplitFields(line));
  }
}

double ParseDouble(const std::string& text, const std::string& file, int line) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || errno == ERANGE) {
    throw InputErrorAt(file, line, "not a number: '" + text + "'");
  }
  if (!std::isfinite(value)) throw InputErrorAt(file, line, "non-finite value: '" + text + "'");
  return value;
}

}  // namespace dynorb
