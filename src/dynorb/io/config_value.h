// Internal to io/ (used by config_schema.cc; not an API for other modules): typed values of
// ConfigSchema fields — parsing from yaml-cpp nodes, assignment through the bound pointer,
// formatting as YAML text — and the OpenCV-FileStorage → YAML normalisation.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "dynorb/io/config_schema.h"

namespace YAML {
class Node;
}  // namespace YAML

namespace dynorb {
namespace config_internal {

using Value =
    std::variant<double, int, bool, std::string, std::vector<double>, std::vector<std::string>>;

// Parses `node` as a value of `type`; throws InputError "<where>: '<path>' expects ...".
Value ParseValue(ConfigValueType type, const YAML::Node& node, const std::string& where,
                 const std::string& path);
// *target (of the C++ type matching `type`) = value.
void AssignValue(ConfigValueType type, void* target, const Value& value);
// YAML text of *target; doubles use the shortest text that reads back to the same double.
std::string FormatValue(ConfigValueType type, const void* target);

// Makes OpenCV-FileStorage YAML acceptable to yaml-cpp, keeping line numbers (see .cc).
std::string NormalizeOpenCvYaml(const std::string& text);
// Replaces newlines by spaces (for comments).
std::string OneLine(std::string s);

}  // namespace config_internal
}  // namespace dynorb
