// Factory of `dynorb run --mode fast` (apps/mode_fast.cc); also a part of `--mode fused`.
#pragma once

#include <memory>

#include "dynorb/dynamic/fast_options.h"
#include "run_modes.h"

namespace dynorb {

class FastModeFactory : public RunModeFactory {
 public:
  void BindConfig(ConfigSchema* schema) override;  // The `fast:` section.
  std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) override;

 private:
  FastOptions options_;
};

}  // namespace dynorb
