// The run modes' YAML sections: each mode's defaults as written to effective_config.yaml, and a
// configuration key overriding them.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <string>

#include "dynorb/core/error.h"
#include "run_modes.h"

namespace dynorb {
namespace {

// The value text of `key` in the YAML section `section` of ToYaml() ("" when absent).
// Section lines are "name:" or "name:  # help".
std::string ValueIn(const std::string& text, const std::string& section, const std::string& key) {
  const std::string yaml = "\n" + text;
  size_t begin = yaml.find("\n" + section + ":\n");
  if (begin == std::string::npos) begin = yaml.find("\n" + section + ":  #");
  if (begin == std::string::npos) return "";
  const size_t end = yaml.find("\n\n", begin + 1);
  const size_t at = yaml.find("\n  " + key + ": ", begin);
  if (at == std::string::npos || (end != std::string::npos && at > end)) return "";
  const size_t value = at + key.size() + 5;
  return yaml.substr(value, yaml.find_first_of(" \n", value) - value);
}

std::string EffectiveYaml(const std::string& mode, const std::string& config_text) {
  ConfigSchema schema;
  std::unique_ptr<RunModeFactory> factory = MakeRunModeFactory(mode);
  if (factory == nullptr) {
    ADD_FAILURE() << "no factory for mode " << mode;
    return "";
  }
  factory->BindConfig(&schema);
  if (!config_text.empty()) schema.LoadString(config_text, "test.yaml");
  return schema.ToYaml();
}

TEST(RunModes, FastAndFusedDefaultsDifferWhereMeasuredAndTheKeyOverridesThem) {
  EXPECT_EQ(ValueIn(EffectiveYaml("fast", ""), "fast", "region_min_seeds"), "3");
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "fast", "region_min_seeds"), "4");
  EXPECT_EQ(
      ValueIn(EffectiveYaml("fused", "fast:\n  region_min_seeds: 2\n"), "fast", "region_min_seeds"),
      "2");
  // The rest of the FAST section is FAST's defaults in both modes.
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "fast", "lk_max_points"),
            ValueIn(EffectiveYaml("fast", ""), "fast", "lk_max_points"));
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "fused", "fast_max_overlap"), "0.5");
  // The residual veto is on in both modes; FAST's quiet schedule in fast mode only.
  EXPECT_EQ(ValueIn(EffectiveYaml("fast", ""), "fast", "residual_static_veto"), "true");
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "fast", "residual_static_veto"), "true");
  EXPECT_EQ(ValueIn(EffectiveYaml("fast", ""), "fast", "quiet_analyse_every"), "2");
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "fast", "quiet_analyse_every"), "1");
  // The semantic quiet and steady schedules in semantic mode only.
  EXPECT_EQ(ValueIn(EffectiveYaml("semantic", ""), "semantic", "quiet_detect_every"), "8");
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "semantic", "quiet_detect_every"), "0");
  EXPECT_EQ(ValueIn(EffectiveYaml("semantic", ""), "semantic", "steady_detect_every"), "8");
  EXPECT_EQ(ValueIn(EffectiveYaml("semantic", ""), "semantic", "steady_min_iou"), "0.85");
  EXPECT_EQ(ValueIn(EffectiveYaml("semantic", ""), "semantic", "steady_after"), "2");
  EXPECT_EQ(ValueIn(EffectiveYaml("fused", ""), "semantic", "steady_detect_every"), "0");
  EXPECT_EQ(ValueIn(EffectiveYaml("semantic", "semantic:\n  steady_detect_every: 0\n"), "semantic",
                    "steady_detect_every"),
            "0");
}

// `semantic.threads` sets OpenCV's thread count for the run only: `dynorb bench` runs every run
// of a suite in one process.
TEST(RunModes, SemanticThreadsLastAsLongAsTheRun) {
  const std::string list = (std::filesystem::temp_directory_path() /
                            ("dynorb_modes_boxes_" + std::to_string(::getpid()) + ".txt"))
                               .string();
  std::ofstream(list) << "1.0 10 10 20 20\n";
  const int before = cv::getNumThreads();
  const int asked = before == 3 ? 2 : 3;
  for (const std::string mode : {"semantic", "fused"}) {
    SCOPED_TRACE(mode);
    {
      ConfigSchema schema;
      std::unique_ptr<RunModeFactory> factory = MakeRunModeFactory(mode);
      factory->BindConfig(&schema);
      schema.LoadString("semantic:\n  threads: " + std::to_string(asked) +
                            "\n  source: boxes\n  list: " + list + "\n",
                        "test.yaml");
      RunModeContext context;
      SystemConfig config;
      context.config = &config;
      std::unique_ptr<KeypointFilter> filter = factory->Create(context);
      ASSERT_NE(filter, nullptr);
      EXPECT_EQ(cv::getNumThreads(), asked);
    }
    EXPECT_EQ(cv::getNumThreads(), before);
  }
  std::filesystem::remove(list);
}

TEST(RunModes, UnknownModeAndBadSectionValueAreInputErrors) {
  EXPECT_THROW(MakeRunModeFactory("no_such_mode"), InputError);
  EXPECT_THROW(EffectiveYaml("fused", "fast:\n  region_min_seeds: 0\n"), InputError);
}

}  // namespace
}  // namespace dynorb
