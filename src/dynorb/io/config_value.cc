#include "dynorb/io/config_value.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "dynorb/core/error.h"

namespace dynorb {
namespace config_internal {
namespace {

double ToDouble(const std::string& text, const std::string& where, const std::string& path) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) {
    throw InputError(where + ": '" + path + "' expects a number, got '" + text + "'");
  }
  return v;
}

std::string FormatDouble(double v) {
  char buf[64];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s = buf;
  if (std::isfinite(v) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        out += c;
    }
  }
  return out + "\"";
}

}  // namespace

// Makes OpenCV-FileStorage YAML (ORB-SLAM2 settings) acceptable to yaml-cpp without changing line
// numbers: comments out a "%YAML:1.0" directive and inserts the missing space in top-level
// "Key:value" lines (e.g. ORB-SLAM2's "Viewer.PointSize:2").
std::string NormalizeOpenCvYaml(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML:", 0) == 0) {
      line = "# " + line;
    } else if (!line.empty() &&
               (std::isalpha(static_cast<unsigned char>(line[0])) || line[0] == '_')) {
      size_t i = 0;
      while (i < line.size() && (std::isalnum(static_cast<unsigned char>(line[i])) ||
                                 line[i] == '_' || line[i] == '.')) {
        ++i;
      }
      if (i + 1 < line.size() && line[i] == ':' &&
          !std::isspace(static_cast<unsigned char>(line[i + 1])) && line[i + 1] != ':') {
        line.insert(i + 1, " ");
      }
    }
    out += line;
    out += '\n';
  }
  return out;
}

std::string OneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

Value ParseValue(ConfigValueType type, const YAML::Node& node, const std::string& where,
                 const std::string& path) {
  using Type = ConfigValueType;
  const bool is_list = type == Type::kDoubleList || type == Type::kStringList;
  if (is_list) {
    if (!node.IsSequence() && !node.IsNull()) {
      throw InputError(where + ": '" + path + "' expects a list, e.g. [a, b]");
    }
    std::vector<double> doubles;
    std::vector<std::string> strings;
    if (node.IsSequence()) {
      for (const YAML::Node& item : node) {
        if (!item.IsScalar())
          throw InputError(where + ": '" + path + "' expects a list of scalars");
        if (type == Type::kDoubleList) {
          doubles.push_back(ToDouble(item.Scalar(), where, path));
        } else {
          strings.push_back(item.Scalar());
        }
      }
    }
    if (type == Type::kDoubleList) return doubles;
    return strings;
  }
  if (!node.IsScalar()) {
    throw InputError(where + ": '" + path + "' expects a single value" +
                     (node.IsNull() ? " but has none" : ""));
  }
  const std::string text = node.Scalar();
  switch (type) {
    case Type::kDouble:
      return ToDouble(text, where, path);
    case Type::kInt: {
      const double v = ToDouble(text, where, path);
      if (v != std::floor(v) || v < INT_MIN || v > INT_MAX) {
        throw InputError(where + ": '" + path + "' expects an integer, got '" + text + "'");
      }
      return static_cast<int>(v);
    }
    case Type::kBool: {
      std::string lower;
      for (char c : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (lower == "true" || lower == "1") return true;
      if (lower == "false" || lower == "0") return false;
      throw InputError(where + ": '" + path + "' expects true/false (or 1/0), got '" + text + "'");
    }
    default:
      return text;
  }
}

void AssignValue(ConfigValueType type, void* target, const Value& value) {
  using Type = ConfigValueType;
  switch (type) {
    case Type::kDouble:
      *static_cast<double*>(target) = std::get<double>(value);
      break;
    case Type::kInt:
      *static_cast<int*>(target) = std::get<int>(value);
      break;
    case Type::kBool:
      *static_cast<bool*>(target) = std::get<bool>(value);
      break;
    case Type::kString:
      *static_cast<std::string*>(target) = std::get<std::string>(value);
      break;
    case Type::kDoubleList:
      *static_cast<std::vector<double>*>(target) = std::get<std::vector<double>>(value);
      break;
    case Type::kStringList:
      *static_cast<std::vector<std::string>*>(target) = std::get<std::vector<std::string>>(value);
      break;
  }
}

std::string FormatValue(ConfigValueType type, const void* target) {
  using Type = ConfigValueType;
  switch (type) {
    case Type::kDouble:
      return FormatDouble(*static_cast<const double*>(target));
    case Type::kInt:
      return std::to_string(*static_cast<const int*>(target));
    case Type::kBool:
      return *static_cast<const bool*>(target) ? "true" : "false";
    case Type::kString:
      return Quote(*static_cast<const std::string*>(target));
    case Type::kDoubleList: {
      std::string s = "[";
      for (double v : *static_cast<const std::vector<double>*>(target)) {
        s += (s.size() > 1 ? ", " : "") + FormatDouble(v);
      }
      return s + "]";
    }
    case Type::kStringList: {
      std::string s = "[";
      for (const std::string& v : *static_cast<const std::vector<std::string>*>(target)) {
        s += (s.size() > 1 ? ", " : "") + Quote(v);
      }
      return s + "]";
    }
  }
  return "";
}

}  // namespace config_internal
}  // namespace dynorb
