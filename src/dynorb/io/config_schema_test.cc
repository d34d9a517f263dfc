#include "dynorb/io/config_schema.h"

#include <gtest/gtest.h>

#include "dynorb/core/error.h"
#include "dynorb/core/test_expect_error.h"

namespace dynorb {
namespace {

// A module-owned options struct, bound from outside io/ as another module would do it.
struct DetectorOptions {
  std::string model = "yolo.onnx";
  double score_threshold = 0.5;
  int input_size = 640;
  bool enabled = true;
  std::vector<std::string> dynamic_classes = {"person"};
  std::vector<double> mean = {0.0, 0.0, 0.0};
  void Validate() const {
    if (score_threshold < 0.0 || score_threshold > 1.0)
      throw InputError("detector.score_threshold out of [0,1]");
  }
};

void Bind(DetectorOptions* d, ConfigSchema* schema, int* validated) {
  schema->Section("detector", "object detector")
      .Add("model", &d->model, "model file")
      .Add("score_threshold", &d->score_threshold, "minimum score")
      .Add("input_size", &d->input_size, "network input size [px]")
      .Add("enabled", &d->enabled, "run the detector")
      .Add("dynamic_classes", &d->dynamic_classes, "classes treated as dynamic")
      .Add("mean", &d->mean, "input mean")
      .OnLoaded([d, validated] {
        d->Validate();
        ++*validated;
      });
}

using testing::ExpectInputError;

TEST(ConfigSchema, ModuleSectionLoadsAllTypes) {
  DetectorOptions d;
  int validated = 0;
  ConfigSchema schema;
  Bind(&d, &schema, &validated);
  schema.LoadString(
      "detector:\n  model: \"net: v2.onnx\"\n  score_threshold: 0.25\n  input_size: 320\n"
      "  enabled: false\n  dynamic_classes: [person, dog]\n  mean: [0.5, 1, 2e-3]\n",
      "test.yaml");
  EXPECT_EQ(d.model, "net: v2.onnx");
  EXPECT_EQ(d.score_threshold, 0.25);
  EXPECT_EQ(d.input_size, 320);
  EXPECT_FALSE(d.enabled);
  EXPECT_EQ(d.dynamic_classes, (std::vector<std::string>{"person", "dog"}));
  EXPECT_EQ(d.mean, (std::vector<double>{0.5, 1.0, 0.002}));
  EXPECT_EQ(validated, 1);
  EXPECT_TRUE(schema.IsSet("detector.input_size"));
  EXPECT_FALSE(schema.IsSet("detector.nope"));

  // Round trip through ToYaml into fresh options.
  DetectorOptions copy;
  copy.dynamic_classes.clear();
  ConfigSchema schema2;
  Bind(&copy, &schema2, &validated);
  schema2.LoadString(schema.ToYaml(), "round_trip");
  EXPECT_EQ(copy.model, d.model);
  EXPECT_EQ(copy.score_threshold, d.score_threshold);
  EXPECT_EQ(copy.input_size, d.input_size);
  EXPECT_EQ(copy.enabled, d.enabled);
  EXPECT_EQ(copy.dynamic_classes, d.dynamic_classes);
  EXPECT_EQ(copy.mean, d.mean);
}

TEST(ConfigSchema, DefaultsKeptAndEmptyDocumentAccepted) {
  DetectorOptions d;
  int validated = 0;
  ConfigSchema schema;
  Bind(&d, &schema, &validated);
  schema.LoadString("", "empty.yaml");
  schema.LoadString("detector:\n", "null_section.yaml");
  schema.LoadString("detector:\n  input_size: 416\n", "partial.yaml");
  EXPECT_EQ(d.input_size, 416);
  EXPECT_EQ(d.model, "yolo.onnx");
  EXPECT_EQ(d.dynamic_classes, (std::vector<std::string>{"person"}));
  EXPECT_FALSE(schema.IsSet("detector.model"));
}

TEST(ConfigSchema, ErrorsDoNotPartiallyAssign) {
  DetectorOptions d;
  int validated = 0;
  ConfigSchema schema;
  Bind(&d, &schema, &validated);
  ExpectInputError([&] { schema.LoadString("detector:\n  input_size: 1\n  bogus: 2\n", "x.yaml"); },
                   "x.yaml:3: unknown key 'detector.bogus'");
  EXPECT_EQ(d.input_size, 640);
  ExpectInputError([&] { schema.LoadString("detector:\n  mean: 3\n", "y.yaml"); },
                   "y.yaml:2: 'detector.mean' expects a list");
  ExpectInputError([&] { schema.LoadString("detector:\n  score_threshold: 2\n", "z.yaml"); },
                   "z.yaml: detector.score_threshold out of [0,1]");
  ExpectInputError([&] { schema.LoadString("detector:\n  model:\n", "w.yaml"); },
                   "'detector.model' expects a single value but has none");
}

TEST(ConfigSchema, OverridesFromText) {
  DetectorOptions d;
  int validated = 0;
  ConfigSchema schema;
  Bind(&d, &schema, &validated);
  double root_value = 1.0;
  schema.Root().Add("Some.value", &root_value, "a root key");
  schema.Override("detector.input_size", "1024");
  schema.Override("detector.dynamic_classes", "[cat]");
  schema.Override("Some.value", "2.5");
  EXPECT_EQ(d.input_size, 1024);
  EXPECT_EQ(d.dynamic_classes, (std::vector<std::string>{"cat"}));
  EXPECT_EQ(root_value, 2.5);
  EXPECT_TRUE(schema.IsSet("Some.value"));
  ExpectInputError([&] { schema.Override("detector.nope", "1"); }, "unknown key 'detector.nope'");
  ExpectInputError([&] { schema.Override("detector.input_size", "big"); }, "expects a number");
}

TEST(ConfigSchema, ProgrammingErrorsInDeclarations) {
  ConfigSchema schema;
  double x = 0.0;
  schema.Root().Add("a", &x, "");
  EXPECT_THROW(schema.Root().Add("a", &x, ""), std::logic_error);
  EXPECT_THROW(schema.Section("a"), std::logic_error);
  EXPECT_THROW(schema.Section("bad name"), std::logic_error);
  EXPECT_THROW(schema.Section("s").Add("dotted.key", &x, ""), std::logic_error);
  EXPECT_EQ(&schema.Section("s"), &schema.Section("s"));
}

}  // namespace
}  // namespace dynorb
