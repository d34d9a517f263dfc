// The TUM RGB-D calibrations of config/tum_fr{1,2,3}.yaml built into the executable, and the rule
// that picks one for a dataset folder without camera.yaml: the folder's name says freiburg1, 2
// or 3, as every TUM RGB-D sequence folder's does (rgbd_dataset_freiburg3_walking_xyz).
#pragma once

#include <optional>
#include <string>

namespace dynorb {

struct BuiltInConfig {
  std::string file;    // The source file in the checkout, e.g. "config/tum_fr3.yaml".
  std::string camera;  // e.g. "TUM RGB-D freiburg3".
  std::string yaml;    // Its text.
};

// The calibration for `dataset_folder` by its last path component; nullopt when the name
// mentions no freiburg camera (or more than one).
std::optional<BuiltInConfig> BuiltInConfigForDataset(const std::string& dataset_folder);

namespace builtin_config_internal {
extern const char* const kTumFreiburg1Yaml;
extern const char* const kTumFreiburg2Yaml;
extern const char* const kTumFreiburg3Yaml;
}  // namespace builtin_config_internal

}  // namespace dynorb
