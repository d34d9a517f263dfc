// ConfigSchema: typed, extensible YAML configuration without exposing yaml-cpp.
//
// A schema is a set of fields, each bound to a variable owned by the caller (an Options struct).
// Fields live either at the top level ("root" keys; dots allowed, e.g. ORB-SLAM2's "Camera.fx")
// or in a named section, written in YAML as a mapping:
//
//   Camera.fx: 517.3          # root key
//   dataset:                  # section "dataset"
//     depth_factor: 5000.0
//
// Load() parses a file once, assigns the bound variables and runs the finalizers (cross-field
// checks, Validate()). Any key that is not declared (and does not match an ignored prefix) is an
// InputError naming the key and the file:line; so are type errors and duplicate keys.
// ToYaml()/Write() emit the current values of all fields (the effective configuration); the
// output loads back to the same values.
//
// Extending: a module that wants its own section does not touch the parser. The layer that owns
// both the options struct and the schema (apps/, system/) binds it:
//   ConfigSchema schema;
//   SystemConfig config;  BindSystemConfig(&config, &schema);          // io/config.h
//   TrackerOptions tracker;
//   schema.Section("tracking", "Tracker options")
//       .Add("min_inliers", &tracker.min_inliers, "inliers needed to accept a pose")
//       .OnLoaded([&] { tracker.Validate(); });
//   schema.Load(path);
//
// Bound variables must outlive the schema's use. Not thread-safe.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace dynorb {

// The value types a field can have (one per ConfigSection::Add overload).
enum class ConfigValueType { kDouble, kInt, kBool, kString, kDoubleList, kStringList };

class ConfigSection {
 public:
  // Declares `key` bound to *value; the current *value is the default. Returns *this to chain.
  ConfigSection& Add(const std::string& key, double* value, const std::string& help);
  ConfigSection& Add(const std::string& key, int* value, const std::string& help);
  ConfigSection& Add(const std::string& key, bool* value,
                     const std::string& help);  // true/false/1/0
  ConfigSection& Add(const std::string& key, std::string* value, const std::string& help);
  ConfigSection& Add(const std::string& key, std::vector<double>* value, const std::string& help);
  ConfigSection& Add(const std::string& key, std::vector<std::string>* value,
                     const std::string& help);
  // Runs after every successful Load() (in registration order), e.g. to call Validate().
  ConfigSection& OnLoaded(std::function<void()> fn);

  const std::string& name() const { return name_; }

 private:
  friend class ConfigSchema;
  using Type = ConfigValueType;
  struct Field {
    std::string key;
    Type type;
    void* value;
    std::string help;
  };
  ConfigSection(std::string name, std::string help, std::vector<std::function<void()>>* finalizers)
      : name_(std::move(name)), help_(std::move(help)), finalizers_(finalizers) {}
  ConfigSection& AddField(const std::string& key, Type type, void* value, const std::string& help);
  const Field* Find(const std::string& key) const;

  std::string name_;  // empty for the root section
  std::string help_;
  std::vector<Field> fields_;
  std::vector<std::function<void()>>* finalizers_;  // owned by the schema, registration order
};

class ConfigSchema {
 public:
  ConfigSchema();
  ~ConfigSchema();
  ConfigSchema(const ConfigSchema&) = delete;
  ConfigSchema& operator=(const ConfigSchema&) = delete;

  // Top-level keys (no section mapping).
  ConfigSection& Root();
  // The section `name` (created on first use; `help` is kept from the first call). Section names
  // must not collide with root keys.
  ConfigSection& Section(const std::string& name, const std::string& help = "");
  // Top-level keys starting with `prefix` are accepted and ignored (e.g. "Viewer." of ORB-SLAM2).
  void IgnorePrefix(const std::string& prefix);

  // Parses the YAML file and assigns the declared fields found in it; fields absent from the
  // file keep their values. ORB-SLAM2/OpenCV files are accepted: a leading "%YAML:1.0" directive
  // and top-level "Key:value" lines without a space after the colon. Throws InputError.
  void Load(const std::string& path);
  // Loads several files in order (later files override earlier ones) and runs the finalizers
  // once at the end, so e.g. a camera file and a system file can be split.
  void LoadFiles(const std::vector<std::string>& paths);
  // Same as Load(path), from text; `source_name` replaces the file name in error messages.
  void LoadString(const std::string& yaml_text, const std::string& source_name);
  // Sets one field from text, e.g. Override("dataset.depth_factor", "1000") or
  // Override("Camera.fx", "500"). For command-line overrides. Runs the finalizers.
  void Override(const std::string& path, const std::string& value_text);

  // True if the field (path "section.key" or root key) was assigned by Load/Override.
  bool IsSet(const std::string& path) const;

  // YAML text of the current values (root keys first, then sections), with help comments.
  std::string ToYaml() const;
  // Writes ToYaml() atomically (AtomicFile).
  void Write(const std::string& path) const;

 private:
  void ParseAndAssign(const std::string& yaml_text, const std::string& source_name);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynorb
