#include "dynorb/io/bench_suite.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dynorb/core/error.h"

namespace dynorb {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseBenchSuite(yaml, "suite.yaml", "/suites");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BenchSuite, ParsesSequencesModesAndSeeds) {
  const BenchSuite suite = ParseBenchSuite(R"(name: quick
repeats: 2
sequences:
  - name: syn
    synthetic: {preset: walking_xyz, seed: 4, frames: 60}
  - name: fr3_w_xyz
    path: rgbd_dataset_freiburg3_walking_xyz
    config: ../config/tum_fr3.yaml
    frames: "0:100"
    tum_name: fr3/walking_xyz
modes:
  - plain
  - {name: fast, config: strict.yaml, optional: true}
)",
                                           "suite.yaml", "/repo/suites");
  EXPECT_EQ(suite.name, "quick");
  ASSERT_EQ(suite.sequences.size(), 2u);
  EXPECT_TRUE(suite.sequences[0].synthetic);
  EXPECT_EQ(suite.sequences[0].synth.preset, "walking_xyz");
  EXPECT_EQ(suite.sequences[0].synth.seed, 4u);
  EXPECT_EQ(suite.sequences[0].synth.frames, 60);
  EXPECT_TRUE(suite.sequences[0].synth.static_twin);
  EXPECT_FALSE(suite.sequences[0].synth.view_loss);  // opt-in
  EXPECT_EQ(suite.sequences[0].line, 4);
  EXPECT_FALSE(suite.sequences[1].synthetic);
  EXPECT_EQ(suite.sequences[1].path, "rgbd_dataset_freiburg3_walking_xyz");
  EXPECT_EQ(suite.sequences[1].config, "/repo/config/tum_fr3.yaml");
  EXPECT_EQ(suite.sequences[1].frames, "0:100");
  EXPECT_EQ(suite.sequences[1].tum_name, "fr3/walking_xyz");
  ASSERT_EQ(suite.modes.size(), 2u);
  EXPECT_EQ(suite.modes[0].label, "plain");
  EXPECT_EQ(suite.modes[1].label, "fast-strict");
  EXPECT_EQ(suite.modes[1].config, "/repo/suites/strict.yaml");
  EXPECT_TRUE(suite.modes[1].optional);
  EXPECT_EQ(suite.modes[1].line, 13);
  EXPECT_EQ(suite.RunSeeds(0), (std::vector<uint64_t>{1, 2}));
  EXPECT_EQ(suite.RunSeeds(3), (std::vector<uint64_t>{1, 2, 3}));
}

// A mode's overlay is applied over the sequence's (or the mode's) config; the label names both.
TEST(BenchSuite, ModeOverlays) {
  const BenchSuite suite = ParseBenchSuite(R"(sequences:
  - {name: syn, synthetic: {preset: walking_xyz, seed: 4, frames: 60}}
modes:
  - fast
  - {name: fast, overlay: configs/fast_descriptors.yaml}
  - {name: fast, config: strict.yaml, overlay: votes.yaml}
  - {name: fast, overlay: votes.yaml, label: fast-votes}
)",
                                           "suite.yaml", "/repo/suites");
  ASSERT_EQ(suite.modes.size(), 4u);
  EXPECT_TRUE(suite.modes[0].overlay.empty());
  EXPECT_EQ(suite.modes[1].overlay, "/repo/suites/configs/fast_descriptors.yaml");
  EXPECT_EQ(suite.modes[1].label, "fast-fast_descriptors");
  EXPECT_EQ(suite.modes[2].label, "fast-strict-votes");
  EXPECT_EQ(suite.modes[3].label, "fast-votes");
  EXPECT_THAT(
      ErrorOf("sequences:\n  - {name: a, path: a}\nmodes:\n  - {name: fast, overlay: [x]}\n"),
      HasSubstr("suite.yaml:4"));
}

TEST(BenchSuite, ViewLossReference) {
  const BenchSuite suite = ParseBenchSuite(
      "sequences:\n  - {name: s, synthetic: {preset: walking_static, view_loss: true}}\nmodes: "
      "[plain]\n",
      "suite.yaml", "/repo");
  ASSERT_EQ(suite.sequences.size(), 1u);
  EXPECT_TRUE(suite.sequences[0].synth.view_loss);
  EXPECT_TRUE(suite.sequences[0].synth.static_twin);
}

TEST(BenchSuite, ExplicitSeeds) {
  const BenchSuite suite = ParseBenchSuite(
      "seeds: [7, 11]\nsequences: [{name: a, path: x}]\nmodes: [plain]\n", "s.yaml", ".");
  EXPECT_EQ(suite.name, "s");
  EXPECT_EQ(suite.RunSeeds(0), (std::vector<uint64_t>{7, 11}));
  EXPECT_EQ(suite.RunSeeds(1), (std::vector<uint64_t>{1}));
  EXPECT_TRUE(suite.pipeline);  // `dynorb run`'s default.
  EXPECT_EQ(suite.pipeline_depth, 4);  // `dynorb run --pipeline-depth`'s default (apps/run_pipeline.h).
  EXPECT_EQ(ParseBenchSuite("pipeline_depth: 2\nsequences: [{name: a, path: x}]\nmodes: [plain]\n", "s.yaml", ".")
                .pipeline_depth,
            2);
  EXPECT_FALSE(ParseBenchSuite("pipeline: false\nsequences: [{name: a, path: x}]\nmodes: [plain]\n", "s.yaml", ".")
                   .pipeline);
  EXPECT_EQ(suite.front_end_threads, 0);  // `dynorb run --front-end-threads`'s default (auto).
  EXPECT_EQ(
      ParseBenchSuite("front_end_threads: 1\nsequences: [{name: a, path: x}]\nmodes: [plain]\n",
                      "s.yaml", ".")
          .front_end_threads,
      1);
  EXPECT_EQ(
      ParseBenchSuite("front_end_threads: 2\nsequences: [{name: a, path: x}]\nmodes: [plain]\n",
                      "s.yaml", ".")
          .front_end_threads,
      2);
  EXPECT_FALSE(suite.preload);  // `dynorb run`'s default: frames decoded while the run goes.
  EXPECT_FALSE(suite.save_map);
  EXPECT_TRUE(ParseBenchSuite("save_map: true\nsequences: [{name: a, path: x}]\nmodes: [plain]\n",
                              "s.yaml", ".")
                  .save_map);
  EXPECT_TRUE(ParseBenchSuite("preload: true\nsequences: [{name: a, path: x}]\nmodes: [plain]\n", "s.yaml", ".")
                  .preload);
}

TEST(BenchSuite, BadSuitesNameFileAndLine) {
  const std::string modes = "modes: [plain]\n";
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, path: x, pth: y}\n" + modes),
              HasSubstr("suite.yaml:2: unknown key 'pth' in a sequence"));
  // A mapping as a key (a stray ',' before '{'; found by fuzzing, session 47): yaml-cpp's
  // conversion error escaped instead of a message naming the file.
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, synthetic:,{preset: p}}\n" + modes),
              HasSubstr("suite.yaml:2: a key of a sequence must be a plain name"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a}\n" + modes),
              HasSubstr("suite.yaml:2: sequence 'a' needs 'path'"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, path: x, synthetic: {preset: p}}\n" + modes),
              HasSubstr("has both 'path' and 'synthetic'"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, path: x}\n  - {name: a, path: y}\n" + modes),
              HasSubstr("suite.yaml:3: duplicate sequence name 'a'"));
  EXPECT_THAT(
      ErrorOf("sequences:\n  - {name: a, path: x}\n  - {name: a_twin, synthetic: {preset: p}}\n" +
              modes),
      HasSubstr("duplicate sequence name"));
  EXPECT_THAT(
      ErrorOf(
          "sequences:\n  - {name: a, path: x}\n  - {name: a_viewloss, synthetic: {preset: p}}\n" +
          modes),
      HasSubstr("suite.yaml:3: duplicate sequence name"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, synthetic: {preset: p, static_twin: false, "
                      "view_loss: true}}\n" +
                      modes),
              HasSubstr("suite.yaml:2: 'view_loss' needs 'static_twin: true'"));
  EXPECT_THAT(
      ErrorOf("sequences:\n  - {name: a, synthetic: {preset: p, view_loss: maybe}}\n" + modes),
      HasSubstr("'view_loss' expects"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: 'a b', path: x}\n" + modes),
              HasSubstr("may only contain"));
  // A name is a folder under --out: '..' wrote a run's outputs outside it (session 54).
  for (const char* name : {".", "..", ".hidden"}) {
    EXPECT_THAT(ErrorOf(std::string("sequences:\n  - {name: '") + name + "', path: x}\n" + modes),
                HasSubstr("may not start with '.'"))
        << name;
  }
  EXPECT_THAT(
      ErrorOf("sequences:\n  - {name: a, path: x}\nmodes:\n  - {name: plain, label: '..'}\n"),
      HasSubstr("may not start with '.'"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, synthetic: {preset: p, frames: -3}}\n" + modes),
              HasSubstr("suite.yaml:2: 'frames' must be >= 1"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, synthetic: {preset: p, frames: many}}\n" + modes),
              HasSubstr("'frames' expects an integer, got 'many'"));
  EXPECT_THAT(ErrorOf("seeds: [1, 2,\n  1]\nsequences:\n  - {name: a, path: /x}\n" + modes),
              HasSubstr("suite.yaml:2: seed 1 is listed twice in 'seeds'"));
  // A sequence's frame range is checked when the suite is read, not when its run starts.
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, path: /x,\n     frames: abc}\n" + modes),
              HasSubstr("suite.yaml:3: 'frames' expects A:B (e.g. 0:300 or 100:), got 'abc'"));
  EXPECT_THAT(ErrorOf("sequences:\n  - {name: a, path: /x, frames: \"5:2\"}\n" + modes),
              HasSubstr("'frames' 5:2 selects no frame"));
  EXPECT_THAT(ErrorOf("repeats: 0\nsequences: [{name: a, path: x}]\n" + modes),
              HasSubstr("suite.yaml:1: 'repeats'"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\n"), HasSubstr("non-empty list 'modes'"));
  EXPECT_THAT(ErrorOf("modes: [plain]\n"), HasSubstr("non-empty list 'sequences'"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain, plain]\n"),
              HasSubstr("duplicate mode 'plain'"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\nrun_mode: fast\n"),
              HasSubstr("suite.yaml:3: 'run_mode' must be sequential or parallel"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\npipeline: maybe\n"),
              HasSubstr("suite.yaml:3: 'pipeline' expects true or false"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\npreload: 2\n"),
              HasSubstr("suite.yaml:3: 'preload' expects true or false"));
  // Too large was reported as too small before session 54.
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\nrepeats: 2000000\n"),
              HasSubstr("suite.yaml:3: 'repeats' must be <= 1000000, got 2000000"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\npipeline_depth: 0\n"),
              HasSubstr("suite.yaml:3: 'pipeline_depth' must be >= 1"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\npipeline_depth: 17\n"),
              HasSubstr("suite.yaml:3: 'pipeline_depth' must be 1..16"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\nfront_end_threads: -1\n"),
              HasSubstr("suite.yaml:3: 'front_end_threads' must be >= 0"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\nfront_end_threads: 3\n"),
              HasSubstr("suite.yaml:3: 'front_end_threads' must be 0 (auto), 1 or 2"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}]\nmodes: [plain]\nmodez: [fast]\n"),
              HasSubstr("suite.yaml:3: unknown key 'modez' in the suite"));
  EXPECT_THAT(ErrorOf("sequences: [{name: a, path: x}\n"), HasSubstr("invalid YAML"));
  EXPECT_THAT(ErrorOf(""), HasSubstr("empty suite file"));
  EXPECT_THROW(LoadBenchSuite("/nonexistent/suite.yaml"), InputError);
}

TEST(BenchSuite, ShippedSuitesParse) {
  for (const char* name :
       {"quick", "synthetic", "tum", "demo", "dynamic_seeds", "walking_full", "fast_methods"}) {
    const BenchSuite suite =
        LoadBenchSuite(std::string(DYNORB_SOURCE_DIR) + "/bench/suites/" + name + ".yaml");
    EXPECT_EQ(suite.name, name);
    EXPECT_FALSE(suite.sequences.empty());
    EXPECT_EQ(suite.modes.front().name, "plain");
  }
}

}  // namespace
}  // namespace dynorb
