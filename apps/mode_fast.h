// Factory of `dynorb run --mode fast` (apps/mode_fast.cc); also a part of `--mode fused`.
#pragma once

#include <memory>

#include "dynorb/dynamic/fast_options.h"
#include "run_modes.h"

namespace dynorb {

class FastModeFactory : public RunModeFactory {
 public:
  // defaults: the values the `fast:` keys take when the configuration does not set them.
  explicit FastModeFactory(const FastOptions& defaults = FastOptions()) : options_(defaults) {}
  void BindConfig(ConfigSchema* schema) override;  // The `fast:` section.
  std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) override;

 private:
  FastOptions options_;
};

}  // namespace dynorb
