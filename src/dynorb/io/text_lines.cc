#include "dynorb/io/text_lines.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "dynorb/core/error.h"

namespace dynorb {

namespace {

// The field as it can be shown in a message: control bytes (NUL, ...) as \xHH.
std::string Printable(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (c >= 0x20 && c != 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02X", c);
      out += hex;
    }
  }
  return out;
}

// Advances `k` over decimal digits of `text`; returns how many.
size_t SkipDigits(const std::string& text, size_t& k) {
  const size_t start = k;
  while (k < text.size() && text[k] >= '0' && text[k] <= '9') ++k;
  return k - start;
}

// Decimal notation only: [+-] digits [. digits] [(e|E) [+-] digits], with at least one digit
// before or after the point. No hex ("0x10"), no spelled values ("inf", "nan"), no spaces or NUL.
bool IsDecimalNumber(const std::string& text) {
  size_t k = 0;
  if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
  size_t mantissa_digits = SkipDigits(text, k);
  if (k < text.size() && text[k] == '.') mantissa_digits += SkipDigits(text, ++k);
  if (mantissa_digits == 0) return false;
  if (k < text.size() && (text[k] == 'e' || text[k] == 'E')) {
    ++k;
    if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
    if (SkipDigits(text, k) == 0) return false;
  }
  return k == text.size();
}

// "nan", "inf", "infinity" in any case, with a sign: what strtod would read as non-finite.
bool IsSpelledNonFinite(const std::string& text) {
  std::string word = text.substr(!text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0);
  for (char& c : word) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return word == "nan" || word == "inf" || word == "infinity" || word.rfind("nan(", 0) == 0;
}

}  // namespace

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
  // Any file that reads as a stream is taken: a regular file, but also a pipe (`--est <(cat f)`,
  // /dev/fd/63) or a character device (/dev/stdin).
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found)
    throw InputError("file not found: " + path);
  if (ec) throw InputError("cannot access " + path + ": " + ec.message());
  if (status.type() == std::filesystem::file_type::directory)
    throw InputError(path + " is a directory, not a file");
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
  if (IsSpelledNonFinite(text))
    throw InputErrorAt(file, line, "non-finite value: '" + Printable(text) + "'");
  if (!IsDecimalNumber(text))
    throw InputErrorAt(file, line, "not a number: '" + Printable(text) + "'");
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size())
    throw InputErrorAt(file, line, "not a number: '" + Printable(text) + "'");
  // ERANGE with a finite value is an underflow ("1e-320", "1e-400"): a tiny or zero value, valid.
  if (!std::isfinite(value))
    throw InputErrorAt(file, line, "number out of range: '" + Printable(text) + "'");
  return value;
}

}  // namespace dynorb
