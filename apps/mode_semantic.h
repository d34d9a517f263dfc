// Factory of `dynorb run --mode semantic` (apps/mode_semantic.cc); also a part of `--mode fused`.
#pragma once

#include <memory>
#include <string>

#include "dynorb/dynamic/semantic_filter.h"
#include "run_modes.h"

namespace dynorb {

class SemanticModeFactory : public RunModeFactory {
 public:
  explicit SemanticModeFactory(const SemanticOptions& defaults = SemanticOptions())
      : options_(defaults) {}
  void BindConfig(ConfigSchema* schema) override;  // The `semantic:` section.
  std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) override;

 private:
  SemanticOptions options_;
  std::string source_ = "detector";
  std::string list_;
  int threads_ = 0;
};

}  // namespace dynorb
