#include "command_registry.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace dynorb {
namespace {
struct Entry {
  std::string name;
  int order;
  CommandSetup setup;
};
std::vector<Entry>& Registry() {
  static std::vector<Entry> registry;
  return registry;
}
}  // namespace

bool RegisterCommand(const std::string& name, int order, CommandSetup setup) {
  Registry().push_back({name, order, std::move(setup)});
  return true;
}

void AddRegisteredCommands(CLI::App& app) {
  auto& registry = Registry();
  std::sort(registry.begin(), registry.end(),
            [](const Entry& a, const Entry& b) { return std::tie(a.order, a.name) < std::tie(b.order, b.name); });
  for (const Entry& entry : registry) entry.setup(app);
}

CLI::Validator NonNegativeInteger() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
          return "expects a non-negative integer, got '" + text + "'";
        errno = 0;
        std::strtoull(text.c_str(), nullptr, 10);
        if (errno == ERANGE) return "expects an integer below 2^64, got '" + text + "'";
        return {};
      },
      "UINT", "non-negative integer");
}

CLI::Validator IntAtLeast(int min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        long long value = 0;
        size_t used = 0;
        try {
          value = std::stoll(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size() || value < min)
          return "expects an integer >= " + std::to_string(min) + ", got '" + text + "'";
        return {};
      },
      "INT>=" + std::to_string(min), "integer at least " + std::to_string(min));
}

}  // namespace dynorb
