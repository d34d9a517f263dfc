// Registry of `dynorb run --mode` values. `plain` (no dynamic handling) is built in; every other
// mode lives in its own apps/mode_<name>.cc and registers a factory at static-initialisation time:
//
//   class FastModeFactory : public RunModeFactory {
//     void BindConfig(ConfigSchema* schema) override { schema->Section("fast").Add(...); }
//     std::unique_ptr<KeypointFilter> Create(const RunModeContext& ctx) override { ... }
//     FastOptions options_;  // bound to the YAML section, defaults in the declaration
//   };
//   const bool kRegistered = RegisterRunMode("fast", "geometric moving-object cues (no DL)",
//                                            [] { return std::make_unique<FastModeFactory>(); });
//
// `dynorb run` creates the factory of the chosen mode, lets it bind its YAML section before the
// config file is loaded (so its keys are accepted, validated and written to
// effective_config.yaml), then calls Create().
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dynorb/dynamic/keypoint_filter.h"
#include "dynorb/features/orb_extractor.h"
#include "dynorb/io/config.h"
#include "dynorb/io/config_schema.h"
#include "dynorb/map/frame_features.h"

namespace dynorb {

struct RunModeContext {
  const SystemConfig* config = nullptr;
  RgbdSensor sensor;
  OrbOptions orb;  // The tracker's ORB settings (config ORBextractor.*).
  std::string dataset;
  std::string models_dir;  // --models (empty: the mode's default lookup).
  uint64_t seed = 0;
};

class RunModeFactory {
 public:
  virtual ~RunModeFactory() = default;
  // Declares the mode's YAML section(s); the bound options must live in the factory.
  virtual void BindConfig(ConfigSchema* /*schema*/) {}
  // Throws InputError for unusable input (e.g. a missing model file).
  virtual std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) = 0;
};

using RunModeMaker = std::function<std::unique_ptr<RunModeFactory>()>;

bool RegisterRunMode(const std::string& name, const std::string& help, RunModeMaker maker);
// "plain" first, then the registered modes in name order.
std::vector<std::string> RunModeNames();
std::string RunModeHelp();
// nullptr for "plain". Throws InputError for an unknown name.
std::unique_ptr<RunModeFactory> MakeRunModeFactory(const std::string& name);

}  // namespace dynorb
