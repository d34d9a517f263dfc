#include "command_registry.h"

#include <algorithm>
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

}  // namespace dynorb
