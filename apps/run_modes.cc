#include "run_modes.h"

#include <map>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {
struct Entry {
  std::string help;
  RunModeMaker maker;
};
std::map<std::string, Entry>& Registry() {
  static std::map<std::string, Entry> registry;
  return registry;
}
}  // namespace

bool RegisterRunMode(const std::string& name, const std::string& help, RunModeMaker maker) {
  Registry()[name] = {help, std::move(maker)};
  return true;
}

std::vector<std::string> RunModeNames() {
  std::vector<std::string> names = {"plain"};
  for (const auto& [name, entry] : Registry()) names.push_back(name);
  return names;
}

std::string RunModeHelp() {
  std::string help = "plain (no dynamic handling: the ORB-SLAM2 baseline)";
  for (const auto& [name, entry] : Registry()) help += "; " + name + " (" + entry.help + ")";
  return help;
}

std::unique_ptr<RunModeFactory> MakeRunModeFactory(const std::string& name) {
  if (name == "plain") return nullptr;
  auto it = Registry().find(name);
  if (it == Registry().end()) throw InputError("unknown --mode '" + name + "'");
  return it->second.maker();
}

}  // namespace dynorb
