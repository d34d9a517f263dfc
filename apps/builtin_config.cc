#include "builtin_config.h"

#include <filesystem>

namespace dynorb {

std::optional<BuiltInConfig> BuiltInConfigForDataset(const std::string& dataset_folder) {
  std::error_code ec;  // "." or "../x": the name of the folder it stands for.
  std::filesystem::path path = std::filesystem::absolute(dataset_folder, ec);
  if (ec) path = dataset_folder;
  path = path.lexically_normal();
  if (path.filename().empty()) path = path.parent_path();  // "DIR/" -> "DIR".
  const std::string name = path.filename().string();
  const char* const texts[] = {builtin_config_internal::kTumFreiburg1Yaml,
                               builtin_config_internal::kTumFreiburg2Yaml,
                               builtin_config_internal::kTumFreiburg3Yaml};
  std::optional<BuiltInConfig> found;
  for (int k = 1; k <= 3; ++k) {
    if (name.find("freiburg" + std::to_string(k)) == std::string::npos) continue;
    if (found) return std::nullopt;  // Two cameras named: no guess.
    found = BuiltInConfig{"config/tum_fr" + std::to_string(k) + ".yaml",
                          "TUM RGB-D freiburg" + std::to_string(k), texts[k - 1]};
  }
  return found;
}

}  // namespace dynorb
