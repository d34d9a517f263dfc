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
  ~SemanticModeFactory() override;  // Gives OpenCV back the thread count Create() changed.
  SemanticModeFactory(const SemanticModeFactory&) = delete;
  SemanticModeFactory& operator=(const SemanticModeFactory&) = delete;
  void BindConfig(ConfigSchema* schema) override;  // The `semantic:` section.
  std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) override;

 private:
  SemanticOptions options_;
  std::string source_ = "detector";
  std::string list_;
  int threads_ = 0;
  int saved_threads_ = -1;  // OpenCV's thread count before Create() set `threads_` (-1: unchanged).
};

}  // namespace dynorb
